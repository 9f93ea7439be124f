"""How high each way of holding a microplate lets the right arm reach: the choice of a grasp for high nests.

Why: the top-down grasp ends at a nest floor of about 0.88 to 0.96 m (`reach_map`), and standing
benches and instruments stand higher. A two-finger gripper whose fingers close across a plate's
short side can turn in two ways while its pads stay on the plate's long walls:
- rolled about the closing axis: the pads turn in their own plane, so their lower edge slopes and only
  a triangle of pad stays on the 14.35 mm wall; the grasp then rises until the lowest pad corner keeps
  the top-down grasp's gap to the nest floor, and slides along the plate until that triangle lies over
  the plate's centre of mass (else the plate twists in the grasp about the closing axis);
- pitched about the plate's long side (the wrist back towards the robot): the pads stay parallel to the
  walls' length but lean across them, so one pad tip stands higher than the other by the plate's width
  times the sine of the pitch and meets the plate's rim instead of its wall.
This module asks the robot model how high each reaches and what each leaves of the pads on the wall,
so the choice is argued from the model, not picked by hand.

    python -m tiago_description.grasp_reach      # the table for the docs (about a minute)

Pure computation; any thread that owns its own `RobotKinematics`.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tiago_description import robot_model as rm
from tiago_description import transforms as tf
from tiago_description.reach_map import highest_reached, reach_model, reaches

MICROPLATE_WALL_M = 0.01435  # an SBS microplate's height: the wall the pads hold
NEST_YAW = -math.pi / 2  # a nest in a row along the bench, as every world file's nests lie ahead of the base


@dataclass(frozen=True)
class Grasp:
    """A way of holding a plate: turned `angle_deg` about the closing axis ("rolled") or about the plate's
    long side ("pitched"), or neither ("top-down")."""

    kind: str
    angle_deg: float = 0.0

    @property
    def label(self) -> str:
        return self.kind if self.kind == "top-down" else f"{self.kind} {self.angle_deg:+.0f} deg"


def floor_gap_m() -> float:
    """The top-down grasp's gap between the pads' tips and the nest floor (motions.yaml's grasp height)."""
    _kinematics, hotel, _seed = reach_model()
    return hotel.grasp_height_m - rm.PAD_TIP


def pad_on_wall_m(grasp: Grasp, wall_m: float = MICROPLATE_WALL_M) -> float:
    """How much pad edge lies on the plate's wall below its top (m along the wall; 0: a pad misses it).

    Top-down: the whole pad width. Rolled: the triangle's length along the sloping lower edge. Pitched:
    the full width if both pad tips stay below the wall's top, else 0 for the higher pad."""
    gap, theta = floor_gap_m(), math.radians(abs(grasp.angle_deg))
    if grasp.kind == "top-down" or theta == 0.0:
        return rm.PAD_WIDTH
    if grasp.kind == "rolled":
        return min(rm.PAD_WIDTH, (wall_m - gap) / math.tan(theta))
    rise = (2 * rm.FINGER_MOUNT_OFFSET + 0.08548) * math.sin(theta)  # one pad tip above the other
    return rm.PAD_WIDTH if gap + rise < wall_m else 0.0


def _pad_corners(rotation: np.ndarray) -> np.ndarray:
    """The corners of both pads (closed on a microplate), turned by `rotation` about the grasping frame's
    origin."""
    half_gap = rm.FINGER_MOUNT_OFFSET + 0.08548 / 2
    corners = [
        (x, side * y, z)
        for x in (rm.PAD_TIP - rm.PAD_LENGTH, rm.PAD_TIP)
        for side in (1.0, -1.0)
        for y in (half_gap, half_gap + rm.PAD_THICKNESS)
        for z in (-rm.PAD_WIDTH / 2, rm.PAD_WIDTH / 2)
    ]
    return np.array(corners) @ rotation.T


def T_site_grasp(grasp: Grasp) -> np.ndarray:
    """The grasping frame in the nest frame (floor centre, z up) for `grasp`, its lowest pad point kept
    at the top-down grasp's gap above the floor."""
    _kinematics, hotel, _seed = reach_model()
    top_down = hotel.T_slot_grasp(approach=False)
    theta = math.radians(grasp.angle_deg)
    if grasp.kind == "top-down" or theta == 0.0:
        return top_down
    c, s = math.cos(theta), math.sin(theta)
    if grasp.kind == "rolled":  # about the grasping frame's y (closing) axis
        turn = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    else:  # pitched: about the grasping frame's z axis (the plate's long side)
        turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    rotation = top_down[:3, :3] @ turn
    corners = _pad_corners(rotation)
    low = corners[np.argmin(corners[:, 2])]
    shift = 0.0
    if grasp.kind == "rolled":
        # the contact triangle runs from the lowest corner back along the plate; its centroid, a third of
        # its length from that corner, goes over the plate's centre
        inward = -math.copysign(1.0, low[0])
        shift = -(low[0] + inward * pad_on_wall_m(grasp) / 3 * c)
    return tf.make_transform((shift, 0.0, floor_gap_m() - low[2]), rotation)


def reached(grasp: Grasp, x: float, y: float, z: float) -> bool:
    """The right arm reaches `grasp` of a nest whose floor centre is at (x, y, z) in base_footprint."""
    kinematics, _hotel, seed = reach_model()
    return reaches(kinematics, tf.from_planar(x, y, NEST_YAW, z) @ T_site_grasp(grasp), seed)


def highest_nest(grasp: Grasp, x: float, y: float) -> float | None:
    """The highest nest floor (m) whose `grasp` the arm reaches at (x, y), to 5 mm; None if none."""
    return highest_reached(lambda z: reached(grasp, x, y, z))


DEFAULT_GRASPS = (
    Grasp("top-down"),
    *(Grasp("rolled", angle) for angle in (20.0, 30.0, 40.0, -20.0, -30.0)),
    *(Grasp("pitched", angle) for angle in (10.0, 20.0, 30.0)),
)
DEFAULT_POINTS = ((0.45, -0.10), (0.45, -0.25), (0.55, -0.10), (0.55, -0.25), (0.65, -0.25))


def table(
    grasps: Sequence[Grasp] = DEFAULT_GRASPS, points: Sequence[tuple[float, float]] = DEFAULT_POINTS
) -> str:
    """A Markdown table: per grasp, the pad length left on a microplate's wall and the highest nest floor
    reached at each point ahead of the base."""
    head = "| grasp | pad on the wall (mm) | " + " | ".join(f"x {x:.2f} y {y:+.2f}" for x, y in points) + " |"
    lines = [head, "|---|---:|" + "---:|" * len(points)]
    for grasp in grasps:
        heights = [highest_nest(grasp, x, y) for x, y in points]
        cells = " | ".join("none" if z is None else f"{z:.2f}" for z in heights)
        lines.append(f"| {grasp.label} | {pad_on_wall_m(grasp) * 1000:.0f} | {cells} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m tiago_description.grasp_reach", description=__doc__.split("\n")[0]
    )
    parser.parse_args(argv)
    sys.stdout.write(table() + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
