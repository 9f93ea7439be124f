"""Where a held plate hangs over its nest, measured in the head camera's depth image (robot software).

Why: a plate is put down where the robot believes the nest is, so every error between the robot's
view of the nest and its hand ends up in the placement. Most of it is the robot's own calibration:
the head camera's mount and the head joints' zero offsets shift every marker it sees (the same few
millimetres at every station, mostly sideways), the arm's joint offsets shift the tool. Between a
pick and a place those errors would cancel if the plate kept the offset it was grasped with, but it
does not: the fingers centre its short side at the pick, and the onboard hotel's pocket (2 mm of
clearance) re-centres it in the base frame, after which the hand holds it a few millimetres off in
a way unrelated to the nest (in replays the nest was believed 7 mm off and the plate released
9.4 mm off it, past the 7.5 mm its ramps capture). Seen in the same image as the
marker - the head unmoved since the marker was sighted, so the camera's error is the same - plate
and nest share the camera's error and their difference is free of it and of the arm's: what is
left is the marker's and the nest's own mounting on the station, and the depth noise.

The plate also hangs turned: the tool's heading carries the marker's heading error and the arm's,
and the hotel's pocket lets it turn in the hand. Turned 0.74 deg and 1.5 mm across, a plate's corner
stayed on a lead-in ramp of station_a/1 in the default lab (a CI run of test_examples; 1.44 deg in
another run of it), so the turn is measured too and the place squares the plate to the nest.

Method: depth pixels are back-projected into the nest's site frame (as the marker gave it); those
at the plate top's height are the plate (the finger pads stand outside its long sides, the palm
above it). The turn comes from the straight edges (`_turn`); in the plate's own axes then, the long
side's ends give the centre along x and the short side's edges, read beyond the pads, give it along
y. A plate whose measured extents do not match its type's (an end hidden by the arm, another body
in the band) gives no measurement; one whose ends are not two parallel lines gives its centre read
in the nest's axes, no turn.

Pure functions on arrays; safe on any thread.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robot_port.types import CameraIntrinsics

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
# Pixels this far inside the long sides are clear of the pads and the sides' edges (the ends' pixels).
CLEAR_OF_SIDES_M = 0.008
# A side measured this much shorter or longer than the plate's is not both of its edges.
EXTENT_TOLERANCE_M = 0.005
EDGE_PERCENTILE = 1.0  # per cent: extents from robust percentiles, symmetric so the centre is unbiased
MIN_POINTS = 200
MAX_TILT_RAD = math.radians(8.0)  # a top tilted further is not a plate held flat by its sides
# The turn: each edge is read as its outermost pixel in bins this long along it (about three pixels
# at 0.7 m); an edge keeps its samples within EDGE_FIT_BAND_M (about a pixel) of its straightest
# line; without an end straight over MIN_EDGE_BINS samples no turn is measured. A plate turned more
# than MAX_YAW_RAD is not believed.
EDGE_BIN_M = 0.004
EDGE_FIT_BAND_M = 0.0015
MIN_EDGE_BINS = 8
MAX_YAW_RAD = math.radians(6.0)


@dataclass(frozen=True)
class HeldPlateSighting:
    """The held plate's centre in the site frame (m) and its measured extents."""

    x: float  # along the plate's long side (the nest's x)
    y: float  # across it
    length: float
    width: float
    points: int
    yaw: float = 0.0  # its turn about the nest's z (rad), from its edges

    @property
    def pose(self) -> tuple[float, float, float]:
        """(x, y, yaw) in the nest's plane."""
        return (self.x, self.y, self.yaw)


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
    the fingers' axis while carried: 1.75 deg measured in one replay, 4 deg in a failed run);
    a level band about the median then cut off both ends, the plate measured 114 mm long and was put
    down unmeasured, 5 mm off, onto a rim."""
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


@dataclass(frozen=True)
class _Extents:
    x: float
    y: float
    length: float
    width: float
    points: int
    along: np.ndarray  # the top's pixels clear of the long sides (its ends' edges)
    across: np.ndarray  # those beyond the pads and within the ends (its long edges)


def _edge_samples(xs: np.ndarray, ys: np.ndarray, outer: float) -> tuple[np.ndarray, np.ndarray]:
    """Points on one straight edge running along x: per bin along x, the bin's mean x and its
    outermost y (``outer`` +1: largest, -1: smallest); bins of fewer than three pixels are skipped."""
    if len(xs) == 0:
        return np.empty(0), np.empty(0)
    bins = np.floor((xs - xs.min()) / EDGE_BIN_M).astype(int)
    centres, edges = [], []
    for index in np.unique(bins):
        chosen = bins == index
        if chosen.sum() >= 3:
            centres.append(float(xs[chosen].mean()))
            edges.append(float(outer * np.max(outer * ys[chosen])))
    return np.array(centres), np.array(edges)


def _line_inliers(runs: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Which samples of one edge lie on its straightest stretch: the largest set within
    EDGE_FIT_BAND_M of a line through two of them (every pair; an edge has a few dozen samples).
    An arm link across an end cuts a corner off it, so half of its samples can lie off the line."""
    best = np.zeros(len(runs), dtype=bool)
    limit = math.tan(MAX_YAW_RAD)
    for i in range(len(runs)):
        for j in range(i + 1, len(runs)):
            if abs(runs[j] - runs[i]) < 2 * EDGE_BIN_M:
                continue
            slope = (values[j] - values[i]) / (runs[j] - runs[i])
            if abs(slope) > limit:
                continue
            near = np.abs(values - values[i] - slope * (runs - runs[i])) < EDGE_FIT_BAND_M
            if near.sum() > best.sum():
                best = near
    return best


def _turn(extents: _Extents) -> float | None:
    """The plate's turn about the nest's z from its edges, or None when no end shows a straight
    stretch of MIN_EDGE_BINS samples.

    A plate turned by yaw has its ends at x = c - tan(yaw) y and its long edges at y = c' + tan(yaw) x.
    The ends are in full view between the long sides unless an arm link crosses one (default lab,
    station_b/2: one end cut off diagonally over half its width), so each keeps its straightest
    stretch (`_line_inliers`) and a first fit takes tan(yaw) from them. The long edges show only
    beyond the pads, in two short stretches, and the arm can hide one (a stretch read 22 mm short);
    their samples on a line of that slope (the offset that keeps the most within a pixel) join the
    last fit for the long baseline they give. Each edge has its own offset in both fits."""
    ends, sides = [], []
    for points, along_x, outer, sign, kind in (
        (extents.along[extents.along[:, 0] > extents.x], 1, 1.0, -1.0, ends),
        (extents.along[extents.along[:, 0] < extents.x], 1, -1.0, -1.0, ends),
        (extents.across[extents.across[:, 1] > extents.y], 0, 1.0, 1.0, sides),
        (extents.across[extents.across[:, 1] < extents.y], 0, -1.0, 1.0, sides),
    ):
        runs, values = _edge_samples(points[:, along_x], points[:, 1 - along_x], outer)
        kind.append((sign * runs, values))
    ends = [
        (runs[kept], values[kept])
        for runs, values in ends
        if (kept := _line_inliers(runs, values)).sum() >= 2
    ]
    if max((len(runs) for runs, _values in ends), default=0) < MIN_EDGE_BINS:
        log.debug("held plate: no end straight over %d samples, no turn", MIN_EDGE_BINS)
        return None
    slope = _common_slope(ends)
    chosen = list(ends)
    for runs, values in sides:
        offsets = values - slope * runs
        counts = [int((np.abs(offsets - offset) < EDGE_FIT_BAND_M).sum()) for offset in offsets]
        if counts and max(counts) >= 2:
            near = np.abs(offsets - offsets[int(np.argmax(counts))]) < EDGE_FIT_BAND_M
            chosen.append((runs[near], values[near]))
    return math.atan(_common_slope(chosen))


def _common_slope(edges: list[tuple[np.ndarray, np.ndarray]]) -> float:
    """The least-squares slope shared by straight edges, each with its own offset."""
    rows = [
        np.column_stack([runs, *(np.full(len(runs), float(k == j)) for j in range(len(edges)))])
        for k, (runs, _values) in enumerate(edges)
    ]
    solution = np.linalg.lstsq(np.vstack(rows), np.concatenate([v for _r, v in edges]), rcond=None)[0]
    return float(solution[0])


def _extents(on_top: np.ndarray, inner: np.ndarray, tool_x: float, pad_width: float) -> _Extents | None:
    """Centre and size of the plate top from pixels in a frame whose x runs along its long side.
    ``on_top``: the top's pixels (x, y); ``inner``: which of them lie clear of the long sides."""
    along = on_top[inner]
    if len(along) < MIN_POINTS:
        log.debug("held plate: %d pixels along, too few", len(along))
        return None
    x_low, x_high = _extent(along[:, 0])
    # The pads stand off the arm's tool position (joint readings) by the camera's calibration error
    # against the arm's, and off the plate's centre by where the hand holds it: either can be several
    # millimetres (pads seen 7 mm off the tool had their outer faces taken for the plate's edges,
    # 95 mm apart). The pads lie within both spans, so both are left out.
    pads_low = min(tool_x, (x_low + x_high) / 2) - pad_width / 2 - BEYOND_PADS_M
    pads_high = max(tool_x, (x_low + x_high) / 2) + pad_width / 2 + BEYOND_PADS_M
    beyond_pads = (on_top[:, 0] < pads_low) | (on_top[:, 0] > pads_high)
    within_ends = (on_top[:, 0] > x_low + 0.004) & (on_top[:, 0] < x_high - 0.004)
    across = on_top[beyond_pads & within_ends]
    if len(across) < MIN_POINTS:
        log.debug("held plate: %d pixels across, too few", len(across))
        return None
    y_low, y_high = _extent(across[:, 1])
    # percentile extents fall short of the edges by about that share of the side on each end
    trim = 1.0 - 2.0 * EDGE_PERCENTILE / 100.0
    return _Extents(
        (x_low + x_high) / 2, (y_low + y_high) / 2, (x_high - x_low) / trim, (y_high - y_low) / trim,
        len(along), along, across,
    )  # fmt: skip


def locate_held_plate(
    points: np.ndarray,
    tool_in_site: np.ndarray,
    plate_bottom_below_tool: float,
    length: float,
    width: float,
    height: float,
    pad_width: float,
    window_m: float = 0.02,
) -> HeldPlateSighting | None:
    """The plate held by a tool at ``tool_in_site`` (grasping frame origin, site frame), or None.

    ``points``: depth pixels in the site frame (``site_points``); ``plate_bottom_below_tool``: how
    far below the grasping frame the plate's bottom is expected (the grasp height); ``length``,
    ``width``, ``height``: the plate type's outer size; ``pad_width``: the finger pads' width along
    the plate's long side (the robot model's), which hides the top face there (0 for a plate resting
    in a nest, the tool then at the nest's centre); ``window_m``: how far beyond the plate's outline
    pixels are read (a neighbour's plate must stay outside it). Percentile extents trim the same
    share at both ends, so the centre stays unbiased while a stray pixel cannot move it.
    The turn comes first, from the four edges; the extents are then read in the plate's own axes (a
    plate turned 1.5 deg reads 2 mm longer in the nest's).
    """
    tool_x, tool_y, tool_z = (float(v) for v in tool_in_site[:3])
    nominal_top = tool_z - plate_bottom_below_tool + height
    near = (np.abs(points[:, 0] - tool_x) < length / 2 + window_m) & (
        np.abs(points[:, 1] - tool_y) < width / 2 + window_m
    )
    inner = near & (np.abs(points[:, 1] - tool_y) < width / 2 - CLEAR_OF_SIDES_M)
    searched = inner & (np.abs(points[:, 2] - nominal_top) < TOP_SEARCH_M)
    if searched.sum() < MIN_POINTS:
        log.debug("held plate: %d pixels near its top's height, too few", int(searched.sum()))
        return None
    top = _top_plane(points[searched], tool_x, tool_y)
    if top is None:
        return None
    on_top = near & (np.abs(points[:, 2] - top(points[:, 0], points[:, 1])) < TOP_BAND_M)
    top_xy = points[on_top][:, :2]
    inner_on_top = inner[on_top]
    first = _extents(top_xy, inner_on_top, tool_x, pad_width)
    if first is None:
        return None
    yaw = _turn(first)
    if yaw is None:  # the centre is still read, in the nest's axes, as before the turn was measured
        log.info("held plate: its turn not measured, its centre read as if square to the nest")
        yaw = 0.0
    if abs(yaw) > MAX_YAW_RAD:
        log.info("held plate: turned %.1f deg, more than a plate held by its sides", math.degrees(yaw))
        return None
    # the pixels turned by -yaw about the tool: x along the plate's long side again
    pivot = np.array([tool_x, tool_y])
    c, s = math.cos(yaw), math.sin(yaw)
    unturn = np.array([[c, s], [-s, c]])  # rotation by -yaw (applied to row vectors as @ unturn.T)
    turned = (top_xy - pivot) @ unturn.T + pivot
    inner_turned = np.abs(turned[:, 1] - tool_y) < width / 2 - CLEAR_OF_SIDES_M
    final = _extents(turned, inner_turned, tool_x, pad_width)
    if final is None:
        return None
    centre = np.array([final.x, final.y]) - pivot
    x, y = (np.array([[c, -s], [s, c]]) @ centre) + pivot
    sighting = HeldPlateSighting(float(x), float(y), final.length, final.width, final.points, yaw)
    if abs(sighting.length - length) > EXTENT_TOLERANCE_M or abs(sighting.width - width) > EXTENT_TOLERANCE_M:
        log.debug(
            "held plate: measured %.1f x %.1f mm, the plate is %.1f x %.1f mm: no measurement",
            1000 * sighting.length, 1000 * sighting.width, 1000 * length, 1000 * width,
        )  # fmt: skip
        return None
    return sighting
