"""Could a TIAGo++ reach each nest of a lab at all: a sweep over every base pose the floor allows.

Why: the loader (`lab_description.serviceability`) judges each nest from the one pose its placement
rules choose for it (far enough back for the camera to see the marker, the row in the middle of the
right arm's band). A refusal is then only as true as those rules. The sweep asks the robot model
without them, as a confirmation: for each nest, every base pose square to the bench whose footprint
(the base disc and the hotel tray ahead of it) keeps the final approach's stopping error clear of the
benches, the dock, the obstacles and the floor's edge; either arm (the left mirrors the right); any
torso height. A nest is served for a labware type when the top-down grasp and the approach that type
needs (a pick's open finger tips over the plate's top, a place's held plate over the nest's brackets)
are reached from one such pose. A nest the sweep finds unserved is out of reach of this robot's
top-down grasp however the lab is worked: a refusal for it is confirmed.

Left out, and said in the printout: headings other than square to the bench (the reach map is made
for that heading); the camera's view and the ways between poses (the loader's other rules); grasps
other than top-down, which the robot does not have.

    python -m tiago_sim.inspection.reach_sweep WORLD.yaml
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from lab_description.floor_gaps import bench_distances, dock_distances, obstacle_distances
from lab_description.serviceability import ALIGN_DRIVE_OVERSHOOT, ALIGN_SIGHTING_ERROR
from lab_description.world import World, load_world
from tiago_description import robot_model as rm
from tiago_description import transforms as tf
from tiago_description.hotel_model import HOTEL_POCKET_SIZE, HOTEL_SLOT_XYZ, TRAY_BEYOND_POCKET
from tiago_description.reach_map import interpolated_ceiling, reach_model, reaches

AHEAD_M = np.round(np.arange(0.30, 0.8001, 0.01), 3)
"""How far ahead of the base a nest may lie (m): the reach map's span."""
LEFT_M = np.round(np.arange(-0.60, 0.6001, 0.01), 3)
"""How far to the base's left (m): the right arm's map and its mirror for the left arm."""
STOP_ERROR_M = ALIGN_SIGHTING_ERROR + ALIGN_DRIVE_OVERSHOOT
"""How much nearer than planned the final approach may stop (m): every pose keeps this clear."""
TOOL_HEIGHT_ERROR_M = 0.006
"""The tool's height error at a nest (up to 6 mm: the calibration errors, grasp-and-release-heights.md)."""
NEST_RIM_M = 0.006
"""How high a nest's brackets rise above its floor (the scene's lead-in ramps)."""
TRAY_LOW_M = 0.58
"""The hotel tray's underside above the floor: an obstacle lower than this meets only the base."""
SWEEP_TERMS = (
    "top-down grasps, every base pose square to the bench that the floor leaves free, either arm, any "
    "torso height; the marker's view and the ways between poses not judged"
)
UNSURE_M = 0.02
"""The reach map is good to this (m); a nest this near its ceiling is asked of the model's IK."""


@dataclass(frozen=True)
class NestReach:
    """One nest as the sweep finds it: the labware types served from some pose, and the best pose."""

    station: str
    nest: int
    height: float  # nest floor above the floor (m)
    served: tuple[str, ...]  # labware types whose grasp and approach are reached from one pose
    not_served: tuple[str, ...]  # the lab's other labware types
    arm: str | None  # the best pose's arm, where the base stands square to the bench
    ahead: float | None  # the nest this far ahead of that pose's base (m)
    left: float | None  # and this far to its left (m)
    headroom: float | None  # how much higher the arm reaches a grasp there than this nest's floor (m)

    def line(self) -> str:
        where = (
            "no pose of the base is free near it"
            if self.arm is None
            else f"best from {self.ahead:.2f} m ahead, {self.left:+.2f} m left, the {self.arm} arm: "
            f"{1000 * self.headroom:+.0f} mm of headroom for the grasp"
        )
        served = f"serves {', '.join(self.served)}" if self.served else "serves no labware type"
        if self.served and self.not_served:
            served += f", not {', '.join(self.not_served)}"
        return f"{self.station} nest {self.nest} ({self.height:.3f} m): {served}; {where}"


def approach_needed(labware_height: float) -> float:
    """How far above a nest the tool must first come for a type (m): a pick's open pad tips clear the
    plate's top, a place's held plate clears the nest's brackets, each by the tool's height error."""
    _kinematics, hotel, _seed = reach_model()
    pad_tips = hotel.grasp_height_m - rm.PAD_TIP  # above the nest floor when the fingers close
    return max(labware_height - pad_tips, NEST_RIM_M) + TOOL_HEIGHT_ERROR_M


@lru_cache(maxsize=2)
def ceiling_grid(arm: str) -> np.ndarray:
    """The highest nest floor whose top-down grasp `arm` reaches, over AHEAD_M x LEFT_M (NaN: none, or
    off the map). The left arm mirrors the right (robot_model), so its map is the right one mirrored."""
    side = 1.0 if arm == "right" else -1.0
    grid = np.full((len(AHEAD_M), len(LEFT_M)), np.nan)
    for i, x in enumerate(AHEAD_M):
        for j, y in enumerate(LEFT_M):
            ceiling = interpolated_ceiling(float(x), side * float(y))
            grid[i, j] = np.nan if ceiling is None else ceiling
    return grid


def tray_outline(step: float = 0.02) -> np.ndarray:
    """Points (x ahead, y left; m) along the hotel tray's outline in base_footprint."""
    length, width = HOTEL_POCKET_SIZE
    front = max(x for x, _, _ in HOTEL_SLOT_XYZ) + (length + TRAY_BEYOND_POCKET[0]) / 2
    back = min(x for x, _, _ in HOTEL_SLOT_XYZ) - (length + TRAY_BEYOND_POCKET[0]) / 2
    side = max(abs(y) for _, y, _ in HOTEL_SLOT_XYZ) + (width + TRAY_BEYOND_POCKET[1]) / 2
    along = np.linspace(back, front, max(2, int(math.ceil((front - back) / step)) + 1))
    across = np.linspace(-side, side, max(2, int(math.ceil(2 * side / step)) + 1))
    edges = [np.column_stack([along, np.full_like(along, y)]) for y in (-side, side)]
    edges += [np.column_stack([np.full_like(across, x), across]) for x in (back, front)]
    return np.vstack(edges)


def free_poses(world: World, xs: np.ndarray, ys: np.ndarray, yaw: float) -> np.ndarray:
    """Which base poses (xs, ys, heading `yaw`) keep the footprint `STOP_ERROR_M` clear of everything."""
    half = world.floor_size / 2
    reach = rm.BASE_RADIUS + STOP_ERROR_M
    free = (np.abs(xs) <= half - reach) & (np.abs(ys) <= half - reach)
    free &= dock_distances(world.dock_pose, xs, ys) >= reach
    for station in world.stations:
        free &= bench_distances(station, xs, ys) >= reach
    for obstacle in world.obstacles:
        free &= obstacle_distances(obstacle, xs, ys) >= reach
    c, s = math.cos(yaw), math.sin(yaw)
    for ahead, left in tray_outline():
        px, py = xs + c * ahead - s * left, ys + s * ahead + c * left
        free &= (np.abs(px) <= half - STOP_ERROR_M) & (np.abs(py) <= half - STOP_ERROR_M)
        for station in world.stations:
            free &= bench_distances(station, px, py) >= STOP_ERROR_M
        for obstacle in world.obstacles:
            if obstacle.height > TRAY_LOW_M:
                free &= obstacle_distances(obstacle, px, py) >= STOP_ERROR_M
    return free


def _reached_by_model(arm: str, ahead: float, left: float, height: float, yaw: float) -> bool:
    """The model's IK (either finger twin, any torso height): the nest at (ahead, left, height) with
    the plate turned `yaw` in base_footprint; the left arm as the right one mirrored."""
    kinematics, grasp, seed = reach_model()
    side = 1.0 if arm == "right" else -1.0
    T_base_grasp = tf.from_planar(ahead, side * left, side * yaw, height) @ grasp.T_slot_grasp(False)
    return reaches(kinematics, T_base_grasp, seed)


def sweep_nest(world: World, station_index: int, nest: int) -> NestReach:
    """Every free pose square to the bench, either arm: which labware types the nest serves."""
    station = world.stations[station_index]
    T_world_site = station.T_world_site(nest)
    height = float(T_world_site[2, 3])
    facing = tf.yaw_of(station.T_world_table())
    forward = np.array([math.cos(facing), math.sin(facing)])
    left_of = np.array([-forward[1], forward[0]])
    ahead, left = np.meshgrid(AHEAD_M, LEFT_M, indexing="ij")
    xs = T_world_site[0, 3] - ahead * forward[0] - left * left_of[0]
    ys = T_world_site[1, 3] - ahead * forward[1] - left * left_of[1]
    free = free_poses(world, xs, ys, facing)
    plate_yaw = tf.yaw_of(T_world_site) - facing
    needs = {name: approach_needed(t.height) for name, t in world.labware_types.items()}
    served: set[str] = set()
    best: tuple[float, str, float, float] | None = None
    for arm in ("right", "left"):
        headroom = np.where(free, ceiling_grid(arm) - height, np.nan)
        if np.isnan(headroom).all():
            continue
        i, j = np.unravel_index(int(np.nanargmax(headroom)), headroom.shape)
        if best is None or headroom[i, j] > best[0]:
            best = (float(headroom[i, j]), arm, float(AHEAD_M[i]), float(LEFT_M[j]))
        for name, need in needs.items():
            if name in served:
                continue
            if np.nanmax(headroom) >= need + UNSURE_M or _served_near_ceiling(
                arm, headroom, need, height, plate_yaw
            ):
                served.add(name)
    order = tuple(name for name in world.labware_types if name in served)
    others = tuple(name for name in world.labware_types if name not in served)
    if best is None:
        return NestReach(station.name, nest, height, order, others, None, None, None, None)
    room, arm, at_ahead, at_left = best
    return NestReach(station.name, nest, height, order, others, arm, at_ahead, at_left, room)


def _served_near_ceiling(
    arm: str, headroom: np.ndarray, need: float, height: float, plate_yaw: float
) -> bool:
    """Where the map puts the need within its error, the model's IK decides, best poses first (a few:
    each costs up to a second)."""
    near = np.argwhere(headroom >= need - UNSURE_M)
    near = near[np.argsort(-headroom[near[:, 0], near[:, 1]])][:4]
    for i, j in near:
        ahead, left = float(AHEAD_M[i]), float(LEFT_M[j])
        if _reached_by_model(arm, ahead, left, height, plate_yaw) and _reached_by_model(
            arm, ahead, left, height + need, plate_yaw
        ):
            return True
    return False


def sweep_world(world: World) -> list[NestReach]:
    """`sweep_nest` for every nest of every station."""
    return [
        sweep_nest(world, index, nest)
        for index, station in enumerate(world.stations)
        for nest in range(1, station.sub_positions + 1)
    ]


def unserved(reaches_: Sequence[NestReach], labware: Sequence[str]) -> list[NestReach]:
    """The nests that serve none of `labware` (a lab's tallest type, say: what the loader asks)."""
    return [reach for reach in reaches_ if not set(labware) & set(reach.served)]


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m tiago_sim.inspection.reach_sweep", description=__doc__.split("\n")[0]
    )
    parser.add_argument("world", help="a world file (checked for its floor plan only)")
    args = parser.parse_args(argv)
    world = load_world(args.world, check_robot=False)
    for reach in sweep_world(world):
        sys.stdout.write(reach.line() + "\n")
    sys.stdout.write(f"({SWEEP_TERMS})\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
