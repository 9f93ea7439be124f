"""How high the arm reaches a nest top-down, mapped over the floor ahead of the base: a generated table.

Why: the world loader and the layout generator ask, for many nests, whether the right arm reaches a
top-down grasp there at any torso height. Each answer near the limit costs about a second of IK
restarts; the highest reachable nest floor changes slowly with the nest's place, so it is found once
per grid point here (bisection on the pinocchio model, to 5 mm), written to `top_down_reach.json`
with the digest of the URDF it came from, and read by interpolation. The loader still runs IK near
the limit; the map only answers where a nest is well above or well below it.

    python -m tiago_description.reach_map --write     # regenerate after the robot model changes
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path

import numpy as np

from tiago_description import robot_model
from tiago_description import transforms as tf
from tiago_description.kinematics import RobotKinematics
from tiago_description.motion_library import HotelGrasp, load_motions

MAP_FILE = Path(__file__).with_name("top_down_reach.json")
GRID_X = tuple(round(0.30 + 0.05 * i, 2) for i in range(11))  # m ahead of the base: 0.30 .. 0.80
GRID_Y = tuple(round(-0.60 + 0.05 * i, 2) for i in range(17))  # m to its left: -0.60 .. 0.20
HEIGHT_RANGE = (0.3, 1.4)  # m: the nest floors searched
HEIGHT_TOLERANCE = 0.005  # m
SCAN_STEP_M = 0.2  # the first reached height is looked for this coarsely (far ahead only high nests are)
REACH_ARM = "right"
_FLIP_ABOUT_APPROACH = tf.make_transform(rotation=np.diag([1.0, -1.0, -1.0]))


@lru_cache(maxsize=1)
def reach_model() -> tuple[RobotKinematics, HotelGrasp, dict[str, float]]:
    """The kinematics, the grasp's geometry and the IK seed (the bench posture) reach is judged with."""
    motions = load_motions()
    seed: dict[str, float] = {}
    for frame in motions.frames_for("Benchtop", REACH_ARM):
        seed.update(frame)
    return RobotKinematics(), motions.hotel, seed


def reaches(kinematics: RobotKinematics, T_base_grasp: np.ndarray, seed: dict[str, float]) -> bool:
    """The right arm reaches the grasp pose, or its twin with the fingers swapped, at any torso height."""
    for twin in (T_base_grasp, T_base_grasp @ _FLIP_ABOUT_APPROACH):
        if kinematics.inverse(REACH_ARM, twin, seed, use_torso=True, restarts=20).success:
            return True
    return False


def reaches_nest(x: float, y: float, z: float) -> bool:
    """The top-down grasp of a nest whose floor centre is at (x, y, z) in base_footprint is reached."""
    kinematics, grasp, seed = reach_model()
    return reaches(kinematics, tf.make_transform((x, y, z)) @ grasp.T_slot_grasp(False), seed)


def model_digest() -> str:
    """Digest of the URDF the map belongs to (the map is stale when the model changes)."""
    return hashlib.sha1(robot_model.build_urdf().encode()).hexdigest()[:12]


def highest_reached(reached: Callable[[float], bool]) -> float | None:
    """The top (m) of the heights in HEIGHT_RANGE for which `reached` holds: the first of the heights
    `SCAN_STEP_M` apart that is reached, going up, then bisection between it and the range's top
    (None: none of them is reached). Reachability is taken to hold on one interval of heights."""
    low, high = HEIGHT_RANGE
    scan = [low + SCAN_STEP_M * k for k in range(int(round((high - low) / SCAN_STEP_M)) + 1)]
    first = next((z for z in scan if reached(z)), None)
    if first is None:
        return None
    if reached(high):
        return high
    low = first
    while high - low > HEIGHT_TOLERANCE:
        middle = (low + high) / 2
        low, high = (middle, high) if reached(middle) else (low, middle)
    return round(low, 4)


def compute(reached_at: Callable[[float, float, float], bool]) -> dict:
    """The map: for each grid point (x, y), the highest nest floor `reached_at(x, y, z)` allows."""
    ceilings = [[highest_reached(lambda z, x=x, y=y: reached_at(x, y, z)) for y in GRID_Y] for x in GRID_X]
    return {"model": model_digest(), "x": list(GRID_X), "y": list(GRID_Y), "ceiling": ceilings}


@lru_cache(maxsize=1)
def _loaded() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    data = json.loads(MAP_FILE.read_text())
    ceiling = np.array([[np.nan if c is None else c for c in row] for row in data["ceiling"]], dtype=float)
    return np.array(data["x"]), np.array(data["y"]), ceiling


def map_model() -> str:
    """The model digest the shipped map was computed for."""
    return str(json.loads(MAP_FILE.read_text())["model"])


def interpolated_ceiling(x: float, y: float) -> float | None:
    """The map's highest reachable nest floor at (x, y), bilinear between grid points; None outside the
    grid or where a neighbouring grid point reaches nothing."""
    xs, ys, ceiling = _loaded()
    if not (xs[0] <= x <= xs[-1] and ys[0] <= y <= ys[-1]):
        return None
    i = min(int(np.searchsorted(xs, x, side="right")) - 1, len(xs) - 2)
    j = min(int(np.searchsorted(ys, y, side="right")) - 1, len(ys) - 2)
    corners = ceiling[i : i + 2, j : j + 2]
    u = (x - xs[i]) / (xs[i + 1] - xs[i])
    v = (y - ys[j]) / (ys[j + 1] - ys[j])
    weights = np.array([[(1 - u) * (1 - v), (1 - u) * v], [u * (1 - v), u * v]])
    if np.isnan(corners[weights > 1e-9]).any():
        return None
    return float((np.where(weights > 1e-9, corners, 0.0) * weights).sum())


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m tiago_description.reach_map", description=__doc__.split("\n")[0]
    )
    parser.add_argument("--write", action="store_true", help=f"recompute and write {MAP_FILE.name}")
    args = parser.parse_args(argv)
    if not args.write:
        sys.stdout.write(f"{MAP_FILE}: model {map_model()}, current model {model_digest()}\n")
        return 0 if map_model() == model_digest() else 1
    MAP_FILE.write_text(json.dumps(compute(reaches_nest), indent=1) + "\n")
    sys.stdout.write(f"wrote {MAP_FILE}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
