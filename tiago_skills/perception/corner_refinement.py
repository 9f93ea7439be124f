"""Sub-pixel marker corners from straight-edge fits, for images too clean for OpenCV's own.

On a perfectly aligned, noise-free render (a simulated robot parked exactly in front of its
marker) OpenCV 5's ArUco detector returns integer corners, sometimes of a visibly rotated
quadrilateral, and its SUBPIX refinement leaves them there. A real camera's blur and noise hide
this; the simulation does not. So the detector only identifies the marker and gives rough
corners, and each side of the black square is then located along many short profiles across
it (where the intensity crosses halfway from black to the quiet zone), a line is fitted
through those edge points, and adjacent lines are intersected. Straight lines stay straight
under a pinhole projection, so this is exact up to sampling; two passes recover from rough
corners a few pixels off.

Pure functions on arrays; safe on any thread.
"""

from __future__ import annotations

import cv2
import numpy as np

PASSES = 2
SAMPLES_PER_SIDE = 24
# Ends of each side are skipped: near the corners the profiles would cross the other side.
SIDE_MARGIN_FRACTION = 0.15
PROFILE_STEP_PX = 0.25
# Profiles reach this fraction of a side inward and outward (a black border cell is 1/6).
PROFILE_REACH_FRACTION = 1.0 / 12.0
MIN_PROFILE_REACH_PX = 2.0
MAX_PROFILE_REACH_PX = 8.0
MIN_EDGE_CONTRAST = 20.0


def _sample_bilinear(grey: np.ndarray, points_xy: np.ndarray) -> np.ndarray:
    """Intensities at sub-pixel positions (x, y), pixel centres at integers."""
    map_xy = points_xy.astype(np.float32).reshape(-1, 1, 2)
    sampled = cv2.remap(grey, map_xy, None, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return sampled.reshape(points_xy.shape[:-1]).astype(np.float64)


def _edge_points(grey: np.ndarray, start: np.ndarray, end: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """Sub-pixel points on the dark-to-light edge near the segment start-end."""
    direction = end - start
    length = float(np.linalg.norm(direction))
    direction /= length
    normal = np.array([-direction[1], direction[0]])
    if normal @ (0.5 * (start + end) - centre) < 0:
        normal = -normal  # point outward, from the black square into the quiet zone
    reach = float(np.clip(PROFILE_REACH_FRACTION * length, MIN_PROFILE_REACH_PX, MAX_PROFILE_REACH_PX))
    offsets = np.arange(-reach, reach + 1e-9, PROFILE_STEP_PX)
    fractions = np.linspace(SIDE_MARGIN_FRACTION, 1.0 - SIDE_MARGIN_FRACTION, SAMPLES_PER_SIDE)
    bases = start + np.outer(fractions * length, direction)
    profiles_xy = bases[:, None, :] + offsets[None, :, None] * normal
    profiles = _sample_bilinear(grey, profiles_xy)
    points = []
    for base, profile in zip(bases, profiles, strict=True):
        dark, light = profile.min(), profile.max()
        if light - dark < MIN_EDGE_CONTRAST:
            continue
        half_level = 0.5 * (dark + light)
        darkest = int(np.argmin(profile))
        above = np.nonzero(profile[darkest:] >= half_level)[0]
        if above.size == 0:
            continue
        k = darkest + int(above[0])
        t0, t1, i0, i1 = offsets[k - 1], offsets[k], profile[k - 1], profile[k]
        crossing = t0 + (half_level - i0) / (i1 - i0) * (t1 - t0)
        points.append(base + crossing * normal)
    return np.asarray(points)


def _fit_line(points: np.ndarray) -> np.ndarray:
    """Homogeneous line (a, b, c), a x + b y + c = 0, fitted by total least squares."""
    centre = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centre, full_matrices=False)
    normal = vt[1]
    return np.array([normal[0], normal[1], -normal @ centre])


def refine_corners(grey: np.ndarray, corners_px: np.ndarray) -> np.ndarray | None:
    """4x2 corners from edge-line fits, same order as ``corners_px``; None if an edge is lost."""
    corners = np.asarray(corners_px, dtype=np.float64).copy()
    for _ in range(PASSES):
        centre = corners.mean(axis=0)
        lines = []
        for side in range(4):
            points = _edge_points(grey, corners[side], corners[(side + 1) % 4], centre)
            if len(points) < SAMPLES_PER_SIDE // 2:
                return None
            lines.append(_fit_line(points))
        refined = np.empty_like(corners)
        for corner in range(4):
            # corner k joins side k-1 (ending at k) and side k (starting at k)
            crossing = np.cross(lines[(corner - 1) % 4], lines[corner])
            if abs(crossing[2]) < 1e-12:
                return None
            refined[corner] = crossing[:2] / crossing[2]
        corners = refined
    return corners
