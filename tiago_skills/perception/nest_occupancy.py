"""Whether a plate lies in a nest, read from the head camera's depth image (robot software).

Why: a stock TIAGo++ has no sensor in a lab's nests, and a lab need not add one. Its head camera
sees the nest, and a plate's top stands its height (14 mm for an SBS plate) above the nest's floor,
several times the depth noise at the 0.6 to 1 m from head to nest (about 1 to 2 mm). So before a
place the robot looks whether the nest is free, and after it whether the plate is there.

Method: the depth pixels are back-projected into the nest's site frame (as the station's marker
gave it: z up from the floor a seated plate rests on). Those whose x and y lie inside the smallest
plate's footprint, shrunk by ``FOOTPRINT_MARGIN_M`` so that the nest's rims and a plate's edges stay
out, are the nest's floor or a plate's top. Their median height decides: above half the lowest
plate's height is a plate, below it the empty floor. Too few such points (the nest out of the image,
hidden behind the arm or the marker's board) or a median well above any plate (something else on
it) is no answer: the caller reports that it could not see, never a guess.

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


@dataclass(frozen=True)
class NestView:
    """What the depth image shows in a nest: `occupied` is None when it shows nothing usable."""

    occupied: bool | None
    height_m: float  # median height of the footprint's points above the nest's floor (nan: none)
    points: int  # depth pixels inside the footprint
    reason: str  # why there is no answer, or what was seen

    @property
    def seen(self) -> bool:
        return self.occupied is not None


def view_nest(
    depth_m: np.ndarray,
    intrinsics: CameraIntrinsics,
    T_site_optical: np.ndarray,
    plate_sizes: Iterable[tuple[float, float, float]],
) -> NestView:
    """Whether the nest whose site frame the camera sees at `T_site_optical` holds a plate of one
    of the lab's types (`plate_sizes`: length, width, height in m)."""
    sizes = np.array(list(plate_sizes), dtype=float).reshape(-1, 3)
    if not len(sizes):
        raise ValueError("no plate types: nothing to look for")
    half_length = sizes[:, 0].min() / 2 - FOOTPRINT_MARGIN_M
    half_width = sizes[:, 1].min() / 2 - FOOTPRINT_MARGIN_M
    lowest, tallest = float(sizes[:, 2].min()), float(sizes[:, 2].max())
    points = site_points(depth_m, intrinsics, T_site_optical)
    inside = (np.abs(points[:, 0]) < half_length) & (np.abs(points[:, 1]) < half_width)
    heights = points[inside, 2]
    heights = heights[heights > -BELOW_FLOOR_M]
    if heights.size < MIN_POINTS:
        return NestView(
            None, float("nan"), int(heights.size), f"only {heights.size} depth pixels in the nest"
        )
    median = float(np.median(heights))
    if median > tallest + ABOVE_PLATES_M:
        reason = f"something {1000 * median:.0f} mm above the nest's floor hides it"
        return NestView(None, median, int(heights.size), reason)
    occupied = bool(median > lowest / 2)
    what = "a plate's top" if occupied else "the empty floor"
    reason = f"{what} at {1000 * median:.1f} mm ({heights.size} pixels)"
    return NestView(occupied, median, int(heights.size), reason)
