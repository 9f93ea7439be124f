"""Whether a plate lies in a nest, read from the head camera's depth image (robot software).

Why: a stock TIAGo++ has no sensor in a lab's nests, and a lab need not add one. Its head camera
sees the nest, and a plate's top stands its height (14 mm for an SBS plate) above the nest's floor,
several times the depth noise at the 0.6 to 1 m from head to nest (about 1 to 2 mm). So before a
place the robot looks whether the nest is free, and after it whether the plate is there.

Method: the depth pixels are back-projected into the nest's site frame (as the station's marker
gave it: z up from the floor a seated plate rests on). Those whose x and y lie inside the smallest
plate's footprint, shrunk by ``FOOTPRINT_MARGIN_M`` so that the nest's rims and a plate's edges stay
out, are the nest's floor or a plate's top. Their median height decides: above half the lowest
plate's height is a plate, below it the empty floor. A plate is seated when its top is level (a plane
fitted to those pixels tilts less than ``MAX_SEATED_TILT_DEG``) and, where the same nest's empty
floor was seen from the same place before, a plate type's height above that floor: one left on a
lead-in's rim stands up to 6 mm up at one end, 3 to 4 deg tilted, which is still a plate in the
nest for a check that it is free, but not a plate placed. Heights are compared with a floor seen,
not with the one the robot believes: the camera's calibration and depth bias put the whole view a
few millimetres up or down (4.6 mm seen over a random layout), the same in both looks. Too few such
points (the nest out of the image, hidden behind the arm or the marker's board) or a median well
above any plate (something else on it) is no answer: the caller reports that it could not see,
never a guess.

Pure functions on arrays; safe on any thread.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from robot_port.types import CameraIntrinsics
from tiago_skills.perception.held_plate import site_points

FOOTPRINT_MARGIN_M = 0.015  # kept clear of the footprint's edges (rims, a plate resting a little off)
MIN_POINTS = 300  # about a seventh of the shrunk footprint's pixels at 0.8 m
BELOW_FLOOR_M = 0.02  # points lower than this under the nest's floor are not on it (a hole, noise)
ABOVE_PLATES_M = 0.03  # a median this far above the tallest plate's top is something else
# A seated plate's top: level within this (the camera's calibration tilts what it sees by a few
# tenths of a degree), at a plate type's height above the floor seen within SEATED_HEIGHT_M.
MAX_SEATED_TILT_DEG = 1.5
SEATED_HEIGHT_M = 0.004


@dataclass(frozen=True)
class NestView:
    """What the depth image shows in a nest: `occupied` is None when it shows nothing usable."""

    occupied: bool | None
    height_m: float  # median height of the footprint's points above the nest's floor (nan: none)
    tilt_deg: float  # of the plane fitted to them (nan: none)
    points: int  # depth pixels inside the footprint
    reason: str  # why there is no answer, or what was seen
    seated: bool = False  # a plate lies level at a plate type's height

    @property
    def seen(self) -> bool:
        return self.occupied is not None


def view_nest(
    depth_m: np.ndarray,
    intrinsics: CameraIntrinsics,
    T_site_optical: np.ndarray,
    plate_sizes: Iterable[tuple[float, float, float]],
    floor_m: float | None = None,
) -> NestView:
    """Whether the nest whose site frame the camera sees at `T_site_optical` holds a plate of one
    of the lab's types (`plate_sizes`: length, width, height in m), and whether it is seated;
    `floor_m`: the height this nest's empty floor was seen at from the same place, if it was."""
    return view_points(site_points(depth_m, intrinsics, T_site_optical), plate_sizes, floor_m)


def view_points(
    points: np.ndarray, plate_sizes: Iterable[tuple[float, float, float]], floor_m: float | None = None
) -> NestView:
    """`view_nest` on depth pixels already in the nest's site frame (`site_points`)."""
    sizes = np.array(list(plate_sizes), dtype=float).reshape(-1, 3)
    if not len(sizes):
        raise ValueError("no plate types: nothing to look for")
    half_length = sizes[:, 0].min() / 2 - FOOTPRINT_MARGIN_M
    half_width = sizes[:, 1].min() / 2 - FOOTPRINT_MARGIN_M
    lowest, tallest = float(sizes[:, 2].min()), float(sizes[:, 2].max())
    inside = (np.abs(points[:, 0]) < half_length) & (np.abs(points[:, 1]) < half_width)
    footprint = points[inside & (points[:, 2] > -BELOW_FLOOR_M)]
    count = len(footprint)
    if count < MIN_POINTS:
        return NestView(None, float("nan"), float("nan"), count, f"only {count} depth pixels in the nest")
    median = float(np.median(footprint[:, 2]))
    tilt = _tilt_deg(footprint)
    if median > tallest + ABOVE_PLATES_M:
        reason = f"something {1000 * median:.0f} mm above the nest's floor hides it"
        return NestView(None, median, tilt, count, reason)
    occupied = bool(median > lowest / 2)
    above_floor = median - (0.0 if floor_m is None else floor_m)
    at_height = floor_m is None or bool(np.min(np.abs(sizes[:, 2] - above_floor)) < SEATED_HEIGHT_M)
    seated = occupied and at_height and tilt < MAX_SEATED_TILT_DEG
    what = ("a seated plate" if seated else "a plate, not seated,") if occupied else "the empty floor"
    reason = f"{what} at {1000 * median:.1f} mm, tilted {tilt:.1f} deg ({count} pixels)"
    return NestView(occupied, median, tilt, count, reason, seated)


def _tilt_deg(points: np.ndarray) -> float:
    """The tilt of the plane z = a x + b y + c fitted to `points` (least squares)."""
    design = np.column_stack([points[:, 0], points[:, 1], np.ones(len(points))])
    (a, b, _c), *_ = np.linalg.lstsq(design, points[:, 2], rcond=None)
    return float(np.degrees(np.arctan(np.hypot(a, b))))
