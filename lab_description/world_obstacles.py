"""Free-standing obstacles of the world file (boxes, cylinders) and where they may stand.

Why a module of its own: the rules for an obstacle are geometry (inside the floor, clear of the
benches, clear of the places where the robot stands and turns), which the schema cannot state and
which needs the stations' derived poses (POIs follow from the nests). Pure and frozen; any thread.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from tiago_description.robot_model import BASE_RADIUS

KEEP_CLEAR_M = 0.62
"""Free radius (m) around every POI, the docked pose and the working poses: the robot turns there,
and its folded arms sweep 0.48 m from the base centre (navigation.planner.ARM_SWEEP_RADIUS_M;
the hotel tray 0.354 m); the planner keeps 5 cm more (INFLATION_RADIUS_M, 0.53 m), and the robot
may stop up to 9 cm off a POI along either axis (the navigation error: 3 cm per axis, 3 sigma, the
campaign's default). At 0.55 m, a fridge 0.47 m from where a drive ended was either grazed by an
arm or left no path (docs/explanation/decisions/room-around-the-robot.md)."""
DOCK_PATH_SAMPLES = 5
DOCK_GAP = 0.002
"""Between the docked robot's rear and the dock's contact plate (m)."""
DOCK_SIZE = (0.10, 0.45, 0.30)
"""The charging dock's box (m): depth along the docked heading, width, height. It stands lower than
the hotel tray's bottom (0.58 m) and the folded arms: only the base's footprint can meet it."""


@dataclass(frozen=True)
class Obstacle:
    """A box (``length`` along its heading x ``width``) or an upright cylinder (``radius`` > 0)
    standing on the floor, centred on (x, y), ``height`` tall. Angles in radians."""

    name: str
    x: float
    y: float
    yaw: float
    length: float = 0.0
    width: float = 0.0
    radius: float = 0.0
    height: float = 1.0

    @property
    def is_cylinder(self) -> bool:
        return self.radius > 0.0

    def corners(self) -> list[tuple[float, float]]:
        """A box's four floor-plan corners (counter-clockwise)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        half_l, half_w = self.length / 2, self.width / 2
        return [
            (self.x + c * dx - s * dy, self.y + s * dx + c * dy)
            for dx, dy in ((half_l, half_w), (-half_l, half_w), (-half_l, -half_w), (half_l, -half_w))
        ]

    def distance_to(self, px: float, py: float) -> float:
        """Floor-plan distance (m) from a point to the obstacle (0 inside)."""
        if self.is_cylinder:
            return max(0.0, math.hypot(px - self.x, py - self.y) - self.radius)
        return _point_rect_distance(px, py, self.x, self.y, self.yaw, self.length, self.width)

    def overlaps_rect(self, x: float, y: float, yaw: float, length: float, width: float) -> bool:
        """Does it overlap a rectangle (a bench's outline) on the floor plan?"""
        if self.is_cylinder:
            return _point_rect_distance(self.x, self.y, x, y, yaw, length, width) < self.radius
        other = Obstacle("", x, y, yaw, length, width)
        return _rects_overlap(self.corners(), other.corners())

    def extent(self) -> tuple[float, float, float, float]:
        """Axis-aligned bounds (min x, min y, max x, max y)."""
        if self.is_cylinder:
            return (self.x - self.radius, self.y - self.radius, self.x + self.radius, self.y + self.radius)
        xs, ys = zip(*self.corners(), strict=True)
        return (min(xs), min(ys), max(xs), max(ys))


def _point_rect_distance(
    px: float, py: float, x: float, y: float, yaw: float, length: float, width: float
) -> float:
    c, s = math.cos(yaw), math.sin(yaw)
    along = c * (px - x) + s * (py - y)
    across = -s * (px - x) + c * (py - y)
    return math.hypot(max(abs(along) - length / 2, 0.0), max(abs(across) - width / 2, 0.0))


def _rects_overlap(first: list[tuple[float, float]], second: list[tuple[float, float]]) -> bool:
    """Separating-axis test of two convex quadrilaterals (touching counts as apart)."""
    for polygon in (first, second):
        for i in range(4):
            (ax, ay), (bx, by) = polygon[i], polygon[(i + 1) % 4]
            normal = (ay - by, bx - ax)
            a = [normal[0] * px + normal[1] * py for px, py in first]
            b = [normal[0] * px + normal[1] * py for px, py in second]
            if max(a) <= min(b) + 1e-9 or max(b) <= min(a) + 1e-9:
                return False
    return True


@dataclass(frozen=True)
class Bench:
    """A bench's outline as the rules need it."""

    name: str
    x: float
    y: float
    yaw: float
    depth: float
    width: float


def placement_problems(
    obstacles: Iterable[Obstacle],
    floor_size: float,
    benches: Iterable[Bench],
    keep_clear: dict[str, tuple[float, float]],
) -> list[tuple[str, str]]:
    """(field, what) for every obstacle outside the floor, on a bench, or within KEEP_CLEAR_M of a
    place where the robot stands (`keep_clear`: what -> (x, y))."""
    problems = []
    half = floor_size / 2
    benches = list(benches)
    for i, obstacle in enumerate(obstacles):
        where = f"obstacles[{i}]"
        low_x, low_y, high_x, high_y = obstacle.extent()
        if min(low_x, low_y) < -half or max(high_x, high_y) > half:
            problems.append(
                (
                    f"{where}.pose",
                    f"{obstacle.name!r} reaches outside the floor ({low_x:.2f} .. {high_x:.2f}, "
                    f"{low_y:.2f} .. {high_y:.2f} m; the floor is -{half:g} .. {half:g} m)",
                )
            )
        for bench in benches:
            if obstacle.overlaps_rect(bench.x, bench.y, bench.yaw, bench.depth, bench.width):
                problems.append((f"{where}.pose", f"{obstacle.name!r} overlaps {bench.name}'s bench"))
        for what, (px, py) in keep_clear.items():
            distance = obstacle.distance_to(px, py)
            if distance < KEEP_CLEAR_M:
                problems.append(
                    (
                        f"{where}.pose",
                        f"{obstacle.name!r} is {distance:.2f} m from {what} at ({px:.2f}, {py:.2f}); "
                        f"keep {KEEP_CLEAR_M:.2f} m free there (the robot's sweep when it turns, "
                        "the planner's margin and the navigation error)",
                    )
                )
    return problems


def bench_overlap_problems(benches: Iterable[Bench]) -> list[tuple[int, str]]:
    """(index of the later bench, what) for every two benches whose outlines overlap on the floor plan.

    Why: two benches cannot stand in the same place, and a generated layout did draw them so: the
    higher bench's top then covered the other's nest, a finger touched it on the way into the nest
    (a bench top 46 mm above the nest's floor) and a plate started inside a bench, unseen by its
    nest's sensor. Benches that touch are apart.
    """
    benches = list(benches)
    problems = []
    for j, later in enumerate(benches):
        other = Obstacle(later.name, later.x, later.y, later.yaw, later.depth, later.width)
        for earlier in benches[:j]:
            if other.overlaps_rect(earlier.x, earlier.y, earlier.yaw, earlier.depth, earlier.width):
                problems.append((j, f"{later.name}'s bench overlaps {earlier.name}'s bench"))
    return problems


def dock_path_points(
    docked: tuple[float, float], approach: tuple[float, float]
) -> dict[str, tuple[float, float]]:
    """Points along the straight docking path, named for the messages."""
    return {
        f"the docking path ({k}/{DOCK_PATH_SAMPLES - 1})": (
            docked[0] + (approach[0] - docked[0]) * k / (DOCK_PATH_SAMPLES - 1),
            docked[1] + (approach[1] - docked[1]) * k / (DOCK_PATH_SAMPLES - 1),
        )
        for k in range(1, DOCK_PATH_SAMPLES - 1)
    }


def dock_box(docked) -> Obstacle:  # noqa: ANN001 - a world.Pose2D (world imports this module)
    """The charging dock as a box on the floor: right behind the base of a robot docked at `docked`
    (the physics scene builds it there, the map draws it, the loader keeps the robot's drives off it)."""
    behind = BASE_RADIUS + DOCK_GAP + DOCK_SIZE[0] / 2
    x, y = docked.x - behind * math.cos(docked.yaw), docked.y - behind * math.sin(docked.yaw)
    return Obstacle("the dock", x, y, docked.yaw, DOCK_SIZE[0], DOCK_SIZE[1], height=DOCK_SIZE[2])
