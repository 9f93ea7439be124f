"""Where a held plate hangs over its nest, measured in the head camera's depth image (robot software).

Why: a plate is put down where the robot believes the nest is, so every error between the robot's
view of the nest and its hand ends up in the placement. Most of it is the robot's own calibration:
the head camera's mount and the head joints' zero offsets shift every marker it sees (the same few
millimetres at every station, mostly sideways), the arm's joint offsets shift the tool. Between a
pick and a place those errors would cancel if the plate kept the offset it was grasped with, but it
does not: the fingers centre its short side at the pick, and the onboard hotel's pocket (2 mm of
clearance) re-centres it in the base frame, after which the hand holds it a few millimetres off in
a way unrelated to the nest (replays of default-lab seed 60000: the nest believed 7 mm off, the
plate released 9.4 mm off it, past the 7.5 mm its ramps capture). Seen in the same image as the
marker - the head unmoved since the marker was sighted, so the camera's error is the same - plate
and nest share the camera's error and their difference is free of it and of the arm's: what is
left is the marker's and the nest's own mounting on the station, and the depth noise.

Method: depth pixels are back-projected into the nest's site frame (as the marker gave it); those
at the plate top's height are the plate (the finger pads stand outside its long sides, the palm
above it). The long side's ends give the centre along x; the short side's edges, read beyond the
pads, give it along y. A plate whose measured extents do not match its type's (an end hidden by the
arm, another body in the band) gives no measurement.

Pure functions on arrays; safe on any thread.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tiago_sim.perception.camera import CameraIntrinsics

log = logging.getLogger(__name__)

# Half-height of the band about the plate top whose pixels count as plate (depth noise is about 1 mm
# at the 0.7 m from head to nest; the plate top is a flat face).
TOP_BAND_M = 0.003
# Where the plate top is looked for about its nominal height (the plate's height in the hand is off by
# the grasp's height error, 2 mm one sigma; a plate tilted 4 deg in the hand has its ends 4.5 mm up
# and down).
TOP_SEARCH_M = 0.010
# Pixels of the short side's edges are read this far beyond the pads' half-width from the tool (the
# pads cover the middle of the long sides).
BEYOND_PADS_M = 0.005
# A side measured this much shorter or longer than the plate's is not both of its edges.
EXTENT_TOLERANCE_M = 0.005
EDGE_PERCENTILE = 1.0  # per cent: extents from robust percentiles, symmetric so the centre is unbiased
MIN_POINTS = 200
MAX_TILT_RAD = math.radians(8.0)  # a top tilted further is not a plate held flat by its sides


@dataclass(frozen=True)
class HeldPlateSighting:
    """The held plate's centre in the site frame (m) and its measured extents."""

    x: float  # along the plate's long side (the nest's x)
    y: float  # across it
    length: float
    width: float
    points: int


def site_points(depth_m: np.ndarray, intrinsics: CameraIntrinsics, T_site_optical: np.ndarray) -> np.ndarray:
    """Every valid depth pixel as a point in the site frame, shape (N, 3)."""
    height, width = depth_m.shape
    u, v = np.meshgrid(np.arange(width), np.arange(height))
    z = depth_m.reshape(-1)
    valid = np.isfinite(z) & (z > intrinsics.near) & (z < intrinsics.far)
    optical = intrinsics.back_project(u.reshape(-1)[valid], v.reshape(-1)[valid], z[valid])
    return optical @ T_site_optical[:3, :3].T + T_site_optical[:3, 3]


def _extent(values: np.ndarray) -> tuple[float, float]:
    low, high = np.percentile(values, [EDGE_PERCENTILE, 100.0 - EDGE_PERCENTILE])
    return float(low), float(high)


def _top_plane(
    searched: np.ndarray, x0: float, y0: float
) -> Callable[[np.ndarray, np.ndarray], np.ndarray] | None:
    """The plate top's plane z(x, y) fitted to the pixels found near its height, or None when it is
    tilted past `MAX_TILT_RAD`. The plate hangs tilted by a degree or more in the hand (it turns about
    the fingers' axis while carried: 1.75 deg measured in random layout 75185, 4 deg in a failed run);
    a level band about the median then cut off both ends, the plate measured 114 mm long and was put
    down unmeasured, 5 mm off, onto a rim (random layouts 75083, 75185 at efb7303)."""
    inliers = np.ones(len(searched), dtype=bool)
    coefficients = np.zeros(3)
    for _ in range(3):  # least squares, then again on the pixels within the band of the last plane
        chosen = searched[inliers]
        if len(chosen) < MIN_POINTS:
            log.debug("held plate: %d pixels on its top's plane, too few", len(chosen))
            return None
        design = np.column_stack([np.ones(len(chosen)), chosen[:, 0] - x0, chosen[:, 1] - y0])
        coefficients = np.linalg.lstsq(design, chosen[:, 2], rcond=None)[0]
        fitted = (
            coefficients[0]
            + coefficients[1] * (searched[:, 0] - x0)
            + coefficients[2] * (searched[:, 1] - y0)
        )
        inliers = np.abs(searched[:, 2] - fitted) < TOP_BAND_M
    tilt = math.atan(math.hypot(coefficients[1], coefficients[2]))
    if tilt > MAX_TILT_RAD:
        log.debug(
            "held plate: its top tilted %.1f deg, more than a plate held by its sides", math.degrees(tilt)
        )
        return None
    a, b, c = (float(v) for v in coefficients)
    return lambda xs, ys: a + b * (xs - x0) + c * (ys - y0)


def locate_held_plate(
    points: np.ndarray,
    tool_in_site: np.ndarray,
    plate_bottom_below_tool: float,
    length: float,
    width: float,
    height: float,
    pad_width: float,
) -> HeldPlateSighting | None:
    """The plate held by a tool at ``tool_in_site`` (grasping frame origin, site frame), or None.

    ``points``: depth pixels in the site frame (``site_points``); ``plate_bottom_below_tool``: how
    far below the grasping frame the plate's bottom is expected (the grasp height); ``length``,
    ``width``, ``height``: the plate type's outer size; ``pad_width``: the finger pads' width along
    the plate's long side (the robot model's), which hides the top face there. Percentile extents
    trim the same share at both ends, so the centre stays unbiased while a stray pixel cannot move it.
    """
    tool_x, tool_y, tool_z = (float(v) for v in tool_in_site[:3])
    nominal_top = tool_z - plate_bottom_below_tool + height
    near = (np.abs(points[:, 0] - tool_x) < length / 2 + 0.02) & (
        np.abs(points[:, 1] - tool_y) < width / 2 + 0.02
    )
    inner = near & (np.abs(points[:, 1] - tool_y) < width / 2 - 0.008)
    searched = inner & (np.abs(points[:, 2] - nominal_top) < TOP_SEARCH_M)
    if searched.sum() < MIN_POINTS:
        log.debug("held plate: %d pixels near its top's height, too few", int(searched.sum()))
        return None
    top = _top_plane(points[searched], tool_x, tool_y)
    if top is None:
        return None
    on_top = near & (np.abs(points[:, 2] - top(points[:, 0], points[:, 1])) < TOP_BAND_M)
    along = points[on_top & inner]
    x_low, x_high = _extent(along[:, 0])
    # The pads stand off the arm's tool position (joint readings) by the camera's calibration error
    # against the arm's, and off the plate's centre by where the hand holds it: either can be several
    # millimetres (random layout 99012: the pads seen 7 mm off the tool, their outer faces taken for
    # the plate's edges, 95 mm wide). The pads lie within both spans, so both are left out.
    pads_low = min(tool_x, (x_low + x_high) / 2) - pad_width / 2 - BEYOND_PADS_M
    pads_high = max(tool_x, (x_low + x_high) / 2) + pad_width / 2 + BEYOND_PADS_M
    beyond_pads = on_top & ((points[:, 0] < pads_low) | (points[:, 0] > pads_high))
    within_ends = (points[:, 0] > x_low + 0.004) & (points[:, 0] < x_high - 0.004)
    across = points[beyond_pads & within_ends]
    if len(along) < MIN_POINTS or len(across) < MIN_POINTS:
        log.debug("held plate: %d pixels along, %d across, too few", len(along), len(across))
        return None
    y_low, y_high = _extent(across[:, 1])
    # percentile extents fall short of the edges by about that share of the side on each end
    trim = 1.0 - 2.0 * EDGE_PERCENTILE / 100.0
    sighting = HeldPlateSighting(
        (x_low + x_high) / 2,
        (y_low + y_high) / 2,
        (x_high - x_low) / trim,
        (y_high - y_low) / trim,
        len(along),
    )
    if abs(sighting.length - length) > EXTENT_TOLERANCE_M or abs(sighting.width - width) > EXTENT_TOLERANCE_M:
        log.debug(
            "held plate: measured %.1f x %.1f mm, the plate is %.1f x %.1f mm: no measurement",
            1000 * sighting.length, 1000 * sighting.width, 1000 * length, 1000 * width,
        )  # fmt: skip
        return None
    return sighting
