"""Global path planning on the occupancy map: A* on the inflated grid, then straight segments.

Why this shape: the robot turns in place at every corner of its path, and there it sweeps a circle
of ``ROBOT_RADIUS_M``: the folded arms (Travel/Tuck) reach 0.48 m sideways from the base centre, the
onboard hotel tray's corner 0.354 m ahead, the base itself 0.265 m. So the planning map is the
static map inflated by that radius plus a margin: a cell free there is a cell where the robot may
stand and turn. A* (8-connected, octile heuristic)
runs on it with a cost that grows near the inflated zone, so paths keep away from benches where
the room allows; the cell path is then cut to the fewest straight segments whose line of sight
stays clear of a wider comfort zone (or, in a narrow passage, of the inflated map).

Start and goal may lie inside the inflated zone (a POI is 0.6 m from its bench, the working pose
0.38 m): the robot may leave the zone only along one straight segment from the start and enter it
only along one straight segment to the goal. That segment is checked against the map inflated by
the base's own radius (the robot drives it without turning); where the tray could not sweep at the
start or goal (clearance below ``ROBOT_RADIUS_M``), the segment must also lie along the robot's
heading there (driven forward or in reverse), so nothing turns where the arms or tray would touch.

Pure (numpy and OpenCV only); any thread. Units: metres, radians.
"""

from __future__ import annotations

import heapq
import math
import time
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from lab_description.world import World
from tiago_description.hotel_model import hotel_sweep_radius
from tiago_description.robot_model import BASE_RADIUS
from tiago_sim.navigation.occupancy_map import OccupancyMap, build_map

ARM_SWEEP_RADIUS_M = 0.48
"""The folded arms' farthest point from the base centre in the travel pose (Travel/Tuck, torso at
0.15 m): arm_*_4_link at 0.479 m, sideways, from 0.74 m above the floor up, so over a bench top too
(tests/tiago_sim/physics/test_sim_collisions.py probes it in PyBullet; an arm grazed bench_c's top
when the robot drove straight at it)."""
ROBOT_RADIUS_M = max(BASE_RADIUS, hotel_sweep_radius(), ARM_SWEEP_RADIUS_M)
"""The circle the robot sweeps when it turns in place (the arms', 0.48 m; the tray's corner is at
0.354 m)."""
INFLATION_MARGIN_M = 0.05
"""Beyond the sweep: the localisation and path-following error the robot may carry (about 3 cm at
the end of a drive) plus 2 cm."""
INFLATION_RADIUS_M = ROBOT_RADIUS_M + INFLATION_MARGIN_M
FOOTPRINT_MARGIN_M = 0.03
"""Around the base's own radius on the straight segment leaving or entering the inflated zone, and
beyond the folded arms' sideways reach along it (the path follower's and localisation's error)."""
ARMS_LOWEST_M = 0.74
"""The folded arms' lowest point beside the base in the travel pose (arm_*_4_link, torso at 0.15 m)."""
ARMS_CLEAR_ABOVE_M = ARMS_LOWEST_M - 0.02
"""What stands no higher than this passes under the folded arms (a low bench: `build_map(above_m=)`);
2 cm for the torso's and the arm joints' error (0.1 deg over the arm's 0.5 m is 1 mm). At 5 cm a
0.712 m bench beside a working pose it had driven into kept the robot from leaving."""
ARMS_HALF_WIDTH_M = ARM_SWEEP_RADIUS_M + FOOTPRINT_MARGIN_M
"""Half the width of the band the folded arms sweep on a straight segment: an obstacle beside the
segment within this is touched by an arm even where the base passes it with room to spare (an arm
grazed a fridge beside such a segment)."""
COMFORT_M = 0.15
"""Straight segments keep this much more than the inflation from obstacles where the room allows."""
COST_RANGE_M = 0.40
"""Within this distance of the inflated zone a cell costs more (up to 1 + COST_WEIGHT)."""
COST_WEIGHT = 3.0
ALONG_HEADING_RAD = 0.05
"""A start or goal segment counts as along the heading within this (the drive's own tolerance)."""
HEURISTIC_WEIGHT = 1.5
"""A* with its heuristic weighted (the octile distance times this): paths at most 1.5 times the
cheapest, found with far fewer expansions; the line-of-sight pass straightens them anyway.
Unweighted, a detour took 12.6 ms median on an idle core, and four times that on a loaded one."""
SEARCH_CELLS = 2
"""A* searches blocks of 2 x 2 map cells (10 cm): a quarter of the expansions; a block is free
only where all its cells are, so a corridor loses at most a cell's width (5 cm) to it, and the
straight segments are then checked on the 5 cm map."""
ESCAPE_DIRECTIONS = 72
ESCAPE_MAX_M = 1.5


def _escape_arms_half_width(distance: float, leaving: bool) -> float:
    """The folded arms' band `distance` along a straight segment out of the start (`leaving`) or into
    the goal. Leaving, the robot stands at the start with its arms folded and touching nothing; backing
    straight out, an arm strays sideways only by the drive's heading error over the distance driven,
    so the margin grows from nothing to FOOTPRINT_MARGIN_M. With the whole margin at the start, an
    arm 0.49 to 0.51 m from a neighbouring bench's corner, where it had worked, kept the robot from
    leaving (random layouts 207020 and 207101: NAVIGATION_FAILED after the pick or the place)."""
    if not leaving:
        return ARMS_HALF_WIDTH_M
    return ARM_SWEEP_RADIUS_M + min(FOOTPRINT_MARGIN_M, math.tan(ALONG_HEADING_RAD) * distance)


@lru_cache(maxsize=64)
def _band_offsets(half_width: float, resolution: float) -> np.ndarray:
    """Offsets across a segment, every half cell from one edge of a band to the other (the escape's
    bands take a few dozen widths: made once each, not per sample of a segment)."""
    samples = math.ceil(2 * half_width / (resolution / 2)) + 1
    offsets = np.linspace(-half_width, half_width, samples)
    offsets.setflags(write=False)  # shared by every call
    return offsets


def _coarsened(grid: OccupancyMap, cost: np.ndarray, factor: int) -> tuple[OccupancyMap, np.ndarray]:
    """A grid of `factor` x `factor` blocks: a block is occupied if any of its cells is, and costs
    what its dearest cell does (the edge beyond the map counts as occupied)."""
    rows, cols = grid.shape
    padded_rows, padded_cols = -(-rows // factor) * factor, -(-cols // factor) * factor
    occupied = np.ones((padded_rows, padded_cols), dtype=bool)
    occupied[:rows, :cols] = grid.occupied
    padded_cost = np.full((padded_rows, padded_cols), math.inf)
    padded_cost[:rows, :cols] = cost
    shape = (padded_rows // factor, factor, padded_cols // factor, factor)
    blocks = occupied.reshape(shape).any(axis=(1, 3))
    block_cost = padded_cost.reshape(shape).max(axis=(1, 3))
    return OccupancyMap(grid.resolution * factor, grid.origin, blocks), block_cost


def _points_free(grid: OccupancyMap, xs: np.ndarray, ys: np.ndarray) -> bool:
    """Every point (x, y) lies in a free cell of the grid (off the grid counts as occupied)."""
    rows = np.floor((ys - grid.origin[1]) / grid.resolution).astype(int)
    cols = np.floor((xs - grid.origin[0]) / grid.resolution).astype(int)
    height, width = grid.shape
    if rows.min() < 0 or cols.min() < 0 or rows.max() >= height or cols.max() >= width:
        return False
    return not bool(grid.occupied[rows, cols].any())


def world_planner(world: World) -> GlobalPlanner:
    """The planner for a world's static map, knowing which benches the folded arms pass over."""
    return GlobalPlanner(build_map(world), build_map(world, above_m=ARMS_CLEAR_ABOVE_M))


class PlanningError(Exception):
    """No path: ``reason`` says why in words ("the goal (1.20, 3.40) is inside an obstacle")."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


@dataclass(frozen=True)
class Plan:
    """Waypoints (x, y) from the start to the goal; ``reverse_first`` / ``reverse_last``: that
    segment is driven backwards (it leaves or enters the inflated zone along the robot's heading)."""

    waypoints: tuple[tuple[float, float], ...]
    reverse_first: bool = False
    reverse_last: bool = False
    planning_s: float = 0.0

    @property
    def length_m(self) -> float:
        return sum(math.dist(a, b) for a, b in zip(self.waypoints, self.waypoints[1:], strict=False))


class GlobalPlanner:
    """Plans on one static map; build once per map (the inflation and cost grids are cached)."""

    def __init__(self, static_map: OccupancyMap, arms_map: OccupancyMap | None = None) -> None:
        """`arms_map`: what reaches the folded arms' height (`build_map(world, above_m=ARMS_CLEAR_ABOVE_M)`;
        default: everything on the static map, as for obstacles of unknown height)."""
        self.static_map = static_map
        self.arms_map = static_map if arms_map is None else arms_map
        clearance = static_map.clearance_m()
        self.clearance = clearance
        self.inflated = static_map.inflated(INFLATION_RADIUS_M)
        self.comfort = static_map.inflated(INFLATION_RADIUS_M + COMFORT_M)
        self.footprint = static_map.inflated(BASE_RADIUS + FOOTPRINT_MARGIN_M)
        beyond = np.clip((clearance - INFLATION_RADIUS_M) / COST_RANGE_M, 0.0, 1.0)
        cost = 1.0 + COST_WEIGHT * (1.0 - beyond)
        cost[self.inflated.occupied] = math.inf
        self.search_grid, search_cost = _coarsened(self.inflated, cost, SEARCH_CELLS)
        self._cost = search_cost.ravel().tolist()
        self._cols = self.search_grid.shape[1]

    # -- the public call ------------------------------------------------------------------
    def plan(self, start: tuple[float, float, float], goal: tuple[float, float, float]) -> Plan:
        """A path from the start pose (x, y, yaw) to the goal pose; raises PlanningError."""
        started = time.perf_counter()
        grid = self.static_map
        # The start is where the robot stands: it may lie inside the footprint margin (a working pose
        # 0.36 m from its bench shows 0.29 m on a 5 cm map), and it leaves by moving away.
        for what, (x, y, _) in (("goal", goal), ("start", start)):
            if not grid.is_free(x, y) or (what == "goal" and not self.footprint.is_free(x, y)):
                raise PlanningError(
                    f"the {what} ({x:.2f}, {y:.2f}) is inside an obstacle or closer than "
                    f"{BASE_RADIUS + FOOTPRINT_MARGIN_M:.2f} m to one"
                )
        if self._segment_free(self.footprint, start[:2], goal[:2]) and self.inflated.is_free(*start[:2]):
            if self.inflated.is_free(*goal[:2]) and self._segment_free(self.inflated, start[:2], goal[:2]):
                return Plan((start[:2], goal[:2]), planning_s=time.perf_counter() - started)
        exit_point, reverse_first = self._edge_point(start, leaving=True)
        entry_point, reverse_last = self._edge_point(goal, leaving=False)
        first, last = self._search_cell_near(exit_point), self._search_cell_near(entry_point)
        cells = None if first is None or last is None else self._astar(first, last)
        if cells is None:
            raise PlanningError(
                f"no path from ({start[0]:.2f}, {start[1]:.2f}) to ({goal[0]:.2f}, {goal[1]:.2f}) "
                f"with {INFLATION_RADIUS_M:.2f} m clearance (the robot's turning circle plus margin)"
            )
        centres = [self.search_grid.centre_of(*cell) for cell in cells]
        middle = self._shortcut([exit_point, *centres, entry_point])
        points = [start[:2]]
        points += [p for p in middle if math.dist(p, points[-1]) > 1e-3]
        if math.dist(goal[:2], points[-1]) > 1e-3:
            points.append(goal[:2])
        points = self._shortcut_ends(points)
        waypoints = tuple((float(x), float(y)) for x, y in points)
        return Plan(waypoints, reverse_first, reverse_last, time.perf_counter() - started)

    # -- start and goal inside the inflated zone ------------------------------------------
    def _edge_point(
        self, pose: tuple[float, float, float], *, leaving: bool
    ) -> tuple[tuple[float, float], bool]:
        """The pose itself if the robot may turn there; else the nearest point free in the inflated
        map along one straight segment clear for the base (along its heading where the tray cannot
        sweep). Returns the point and whether that segment is driven in reverse."""
        x, y, yaw = pose
        if self.inflated.is_free(x, y):
            return (x, y), False
        row, col = self.static_map.cell_of(x, y)
        may_turn = self.clearance[row, col] >= ROBOT_RADIUS_M
        if may_turn:
            directions = [2 * math.pi * k / ESCAPE_DIRECTIONS for k in range(ESCAPE_DIRECTIONS)]
        else:  # leaving: drive along the heading; entering: arrive along the goal heading
            directions = [yaw, yaw + math.pi]
        best: tuple[float, tuple[float, float], bool] | None = None
        step = self.static_map.resolution / 2
        here = float(self.clearance[row, col])
        for direction in directions:
            dx, dy = math.cos(direction), math.sin(direction)
            distance = 0.0
            while distance <= ESCAPE_MAX_M:
                point = (x + dx * distance, y + dy * distance)
                if not self._base_clear(point, leaving, here):
                    break
                if not self._arms_clear(point, direction, _escape_arms_half_width(distance, leaving)):
                    break
                if self.inflated.is_free(*point):
                    if best is None or distance < best[0]:
                        ahead = math.cos(direction - yaw) > 0.0
                        # where it cannot turn, leaving backwards or arriving from ahead of the goal
                        # runs the segment in reverse
                        reverse = not may_turn and (not ahead if leaving else ahead)
                        best = (distance, point, reverse)
                    break
                distance += step
        if best is None:
            what = "start" if leaving else "goal"
            rule = "in any direction" if may_turn else "along its heading (it cannot turn there)"
            band = f"{ARM_SWEEP_RADIUS_M:.2f} m at first, then " if leaving else ""
            band += f"{ARMS_HALF_WIDTH_M:.2f} m"
            raise PlanningError(
                f"the {what} ({x:.2f}, {y:.2f}) is {self.clearance[row, col]:.2f} m from an obstacle and "
                f"no straight segment {rule} reaches {INFLATION_RADIUS_M:.2f} m clearance "
                f"within {ESCAPE_MAX_M} m with nothing within {band} beside it (the folded arms)"
            )
        return best[1], best[2]

    def _base_clear(self, point: tuple[float, float], leaving: bool, start_clearance: float) -> bool:
        """The base may pass `point`: clear of the footprint margin, or (leaving a start inside it)
        no nearer an obstacle than the start itself."""
        if self.footprint.is_free(*point):
            return True
        row, col = self.static_map.cell_of(*point)
        inside = self.static_map.inside(row, col)
        return leaving and inside and float(self.clearance[row, col]) >= start_clearance

    # -- the grid search ------------------------------------------------------------------
    def _search_cell_near(self, point: tuple[float, float]) -> tuple[int, int] | None:
        """The search cell holding `point`, or (a search cell is free only where all its map cells
        are) the nearest free one within two cells whose centre the point sees on the inflated map."""
        row, col = self.search_grid.cell_of(*point)
        candidates = sorted(
            ((row + dr, col + dc) for dr in range(-2, 3) for dc in range(-2, 3)),
            key=lambda cell: math.dist(point, self.search_grid.centre_of(*cell)),
        )
        for cell in candidates:
            if self.search_grid.inside(*cell) and not self.search_grid.occupied[cell]:
                if cell == (row, col) or self._segment_free(
                    self.inflated, point, self.search_grid.centre_of(*cell)
                ):
                    return cell
        return None

    def _astar(self, start: tuple[int, int], goal: tuple[int, int]) -> list[tuple[int, int]] | None:
        """Cells from start to goal on the cost grid (lists, not numpy: scalar access is faster)."""
        cols = self._cols
        cost = self._cost
        rows = len(cost) // cols
        if not (
            0 <= start[0] < rows and 0 <= goal[0] < rows and 0 <= start[1] < cols and 0 <= goal[1] < cols
        ):
            return None
        begin, end = start[0] * cols + start[1], goal[0] * cols + goal[1]
        if math.isinf(cost[begin]) or math.isinf(cost[end]):
            return None
        goal_row, goal_col = goal
        diagonal = math.sqrt(2.0)
        steps = [(-1, 0, 1.0), (1, 0, 1.0), (0, -1, 1.0), (0, 1, 1.0)]
        steps += [(-1, -1, diagonal), (-1, 1, diagonal), (1, -1, diagonal), (1, 1, diagonal)]
        moves = [(dr * cols + dc, dr, dc, 0.5 * length) for dr, dc, length in steps]
        best = [math.inf] * len(cost)
        came_from = [-1] * len(cost)
        best[begin] = 0.0
        frontier = [(0.0, 0.0, begin)]
        weight = HEURISTIC_WEIGHT
        pop, push, inf = heapq.heappop, heapq.heappush, math.inf
        while frontier:
            _, here, current = pop(frontier)
            if current == end:
                break
            if here > best[current]:
                continue  # a stale entry: a cheaper way here was found after it was queued
            row, col = divmod(current, cols)
            own = cost[current]
            for offset, dr, dc, half_length in moves:
                r, c = row + dr, col + dc
                if r < 0 or r >= rows or c < 0 or c >= cols:
                    continue
                neighbour = current + offset
                step_cost = cost[neighbour]
                if step_cost == inf:
                    continue
                total = here + half_length * (step_cost + own)
                if total < best[neighbour]:
                    best[neighbour] = total
                    came_from[neighbour] = current
                    ar, ac = abs(goal_row - r), abs(goal_col - c)
                    heuristic = max(ar, ac) + (diagonal - 1.0) * min(ar, ac)
                    push(frontier, (total + weight * heuristic, total, neighbour))
        if best[end] == inf:
            return None
        cells = []
        node = end
        while node != -1:
            cells.append(divmod(node, cols))
            node = came_from[node]
        return cells[::-1]

    # -- straight segments ----------------------------------------------------------------
    def _arms_clear(
        self, point: tuple[float, float], direction: float, half_width: float = ARMS_HALF_WIDTH_M
    ) -> bool:
        """Nothing as high as the folded arms beside `point` within `half_width`, across a straight
        segment driven along `direction` (the line through the point at right angles to it)."""
        grid, offsets = self.arms_map, _band_offsets(round(half_width, 4), self.arms_map.resolution)
        return _points_free(
            grid, point[0] - math.sin(direction) * offsets, point[1] + math.cos(direction) * offsets
        )

    def _segment_free(self, grid: OccupancyMap, a: tuple[float, float], b: tuple[float, float]) -> bool:
        """Every point of the segment lies in a free cell (sampled at a quarter cell)."""
        samples = max(2, int(math.dist(a, b) / (grid.resolution / 4)) + 1)
        t = np.linspace(0.0, 1.0, samples)
        return _points_free(grid, a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t)

    def _shortcut(self, points: list[tuple[float, float]]) -> list[tuple[float, float]]:
        """Greedy line of sight: from each kept point, on to the farthest one in sight (comfort
        zone first; the inflated map where the path itself runs closer)."""
        kept = [points[0]]
        i = 0
        while i < len(points) - 1:
            j = self._farthest_in_sight(points, i, self.comfort)
            if j == i + 1:
                j = self._farthest_in_sight(points, i, self.inflated)
            kept.append(points[j])
            i = j
        return kept

    def _farthest_in_sight(self, points: list[tuple[float, float]], i: int, grid: OccupancyMap) -> int:
        for j in range(len(points) - 1, i + 1, -1):
            if self._segment_free(grid, points[i], points[j]):
                return j
        return i + 1

    def _shortcut_ends(self, points: list[tuple[float, float]]) -> list[tuple[float, float]]:
        """Drop a waypoint next to the start or goal where the straight line skips it safely
        (both ends must stay where the robot may turn)."""
        changed = True
        while changed and len(points) > 2:
            changed = False
            for index in range(1, len(points) - 1):
                before, after = points[index - 1], points[index + 1]
                ends_ok = self.inflated.is_free(*before) and self.inflated.is_free(*after)
                if ends_ok and self._segment_free(self.inflated, before, after):
                    del points[index]
                    changed = True
                    break
        return points
