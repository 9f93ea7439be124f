"""ArUco marker pose from camera pixels: detection, robust PnP, optional depth refinement.

Works only on the image (and optionally the depth image); it never asks the simulator where
anything is, so the same code would run on the real head camera.

Pose rules learnt the hard way (see the shared notes): OpenCV 5 has no
``estimatePoseSingleMarkers``, so the pose comes from ``solvePnP``; ``IPPE_SQUARE`` can return
a wrong pose for a marker seen exactly fronto-parallel and rotated 180 deg, so every candidate
(both IPPE solutions, SQPNP) is refined and scored by its reprojection error, and the best wins.
Corners come from straight-edge fits (corner_refinement), not from the detector alone.
With a depth image, a plane fitted to the marker's depth pixels is cut by the four corner rays
and the pose is the rigid fit to those 3D corners: the plane fixes distance and tilt, where a
small marker's PnP pose is weakest and where its two-fold (flip) ambiguity lives.

Pure functions on arrays; safe on any thread.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import cv2
import numpy as np

from robot_port.types import CameraIntrinsics
from tiago_description.transforms import make_transform
from tiago_skills.perception.corner_refinement import refine_corners

logger = logging.getLogger(__name__)

ARUCO_DICTIONARY = cv2.aruco.DICT_4X4_50
# A correct pose of a cleanly detected marker reprojects within a pixel; beyond this, give up.
MAX_REPROJECTION_ERROR_PX = 3.0
# Fraction of the marker polygon (about its centre) whose depth pixels feed the plane fit.
DEPTH_SAMPLE_SHRINK = 0.8
MIN_DEPTH_SAMPLES = 30


@dataclass(frozen=True)
class MarkerObservation:
    """One marker seen by the camera; poses in metres, corners in OpenCV pixel coordinates."""

    marker_id: int
    T_optical_marker: np.ndarray
    reprojection_error_px: float
    # 4x2: the marker's own top-left, top-right, bottom-right, bottom-left corners.
    corners_px: np.ndarray
    distance_m: float
    depth_refined: bool
    marker_size_m: float


def _make_detector() -> cv2.aruco.ArucoDetector:
    parameters = cv2.aruco.DetectorParameters()
    parameters.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    parameters.cornerRefinementWinSize = 3
    parameters.cornerRefinementMinAccuracy = 0.01
    parameters.cornerRefinementMaxIterations = 50
    return cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(ARUCO_DICTIONARY), parameters)


def marker_object_points(marker_size_m: float) -> np.ndarray:
    """Corners of the black square in the marker frame, in the detector's (and IPPE's) order."""
    half = 0.5 * marker_size_m
    return np.array([[-half, half, 0.0], [half, half, 0.0], [half, -half, 0.0], [-half, -half, 0.0]])


def find_marker_corners(rgb: np.ndarray, marker_id: int) -> np.ndarray | None:
    """4x2 sub-pixel corners of ``marker_id`` (the largest if seen twice), or None."""
    grey = cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY) if rgb.ndim == 3 else rgb
    corners, ids, _ = _make_detector().detectMarkers(grey)
    if ids is None:
        return None
    matches = [c.reshape(4, 2) for c, i in zip(corners, ids.ravel(), strict=True) if int(i) == marker_id]
    if not matches:
        return None
    rough = max(matches, key=lambda quad: cv2.contourArea(quad.astype(np.float32))).astype(np.float64)
    refined = refine_corners(grey, rough)
    if refined is None:
        logger.debug("marker %d: edge refinement failed, keeping the detector's corners", marker_id)
        return rough
    return refined


def _reprojection_rms(object_points, image_points, rvec, tvec, camera_matrix) -> float:
    projected, _ = cv2.projectPoints(object_points, rvec, tvec, camera_matrix, None)
    return float(np.sqrt(np.mean(np.sum((projected.reshape(-1, 2) - image_points) ** 2, axis=1))))


def _candidate_poses(
    object_points, image_points, camera_matrix
) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """Refined PnP candidates (rvec, tvec, rms px), best first."""
    seeds: list[tuple[np.ndarray, np.ndarray]] = []
    count, rvecs, tvecs, _ = cv2.solvePnPGeneric(
        object_points, image_points, camera_matrix, None, flags=cv2.SOLVEPNP_IPPE_SQUARE
    )
    seeds += [(rvecs[k], tvecs[k]) for k in range(count)]
    ok, rvec, tvec = cv2.solvePnP(object_points, image_points, camera_matrix, None, flags=cv2.SOLVEPNP_SQPNP)
    if ok:
        seeds.append((rvec, tvec))
    candidates = []
    for rvec, tvec in seeds:
        if float(tvec.ravel()[2]) <= 0.0:
            continue
        rvec_refined, tvec_refined = cv2.solvePnPRefineLM(
            object_points, image_points, camera_matrix, None, rvec.copy(), tvec.copy()
        )
        for r, t in ((rvec, tvec), (rvec_refined, tvec_refined)):
            error = _reprojection_rms(object_points, image_points, r, t, camera_matrix)
            candidates.append((r.reshape(3), t.reshape(3), error))
    candidates.sort(key=lambda candidate: candidate[2])
    return candidates


def _depth_plane(
    depth_m: np.ndarray, corners_px: np.ndarray, intrinsics: CameraIntrinsics
) -> tuple[np.ndarray, np.ndarray] | None:
    """(point, unit normal toward the camera) of the plane through the marker's depth pixels."""
    centre = corners_px.mean(axis=0)
    polygon = centre + DEPTH_SAMPLE_SHRINK * (corners_px - centre)
    mask = np.zeros(depth_m.shape, dtype=np.uint8)
    cv2.fillConvexPoly(mask, np.round(polygon).astype(np.int32), 1)
    rows, cols = np.nonzero(mask)
    z = depth_m[rows, cols].astype(np.float64)
    valid = np.isfinite(z) & (z > intrinsics.near) & (z < intrinsics.far * 0.999)
    if np.count_nonzero(valid) < MIN_DEPTH_SAMPLES:
        return None
    z, rows, cols = z[valid], rows[valid], cols[valid]
    points = intrinsics.back_project(cols, rows, z)
    origin = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - origin, full_matrices=False)
    normal = vt[2]
    if normal @ origin > 0:
        normal = -normal
    return origin, normal


def _fit_rigid(points_from: np.ndarray, points_to: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares rotation and translation taking ``points_from`` onto ``points_to`` (Kabsch)."""
    centre_from, centre_to = points_from.mean(axis=0), points_to.mean(axis=0)
    covariance = (points_from - centre_from).T @ (points_to - centre_to)
    u, _, vt = np.linalg.svd(covariance)
    reflection_fix = np.diag([1.0, 1.0, np.sign(np.linalg.det(vt.T @ u.T))])
    rotation = vt.T @ reflection_fix @ u.T
    return rotation, centre_to - rotation @ centre_from


def _refine_with_depth(
    object_points: np.ndarray,
    depth_m: np.ndarray,
    corners_px: np.ndarray,
    intrinsics: CameraIntrinsics,
) -> tuple[np.ndarray, np.ndarray] | None:
    """(rotation, translation) from the corner rays cut by the marker plane seen in depth.

    The plane fixes distance and tilt (where a small marker's PnP pose is weakest and where its
    two-fold ambiguity lives); the corners fix the position in the plane and the in-plane angle.
    """
    plane = _depth_plane(depth_m, corners_px, intrinsics)
    if plane is None:
        return None
    plane_point, plane_normal = plane
    rays = np.linalg.solve(intrinsics.matrix(), np.column_stack([corners_px, np.ones(4)]).T).T
    denominators = rays @ plane_normal
    if np.any(np.abs(denominators) < 1e-9):
        return None
    corners_3d = rays * (float(plane_normal @ plane_point) / denominators)[:, None]
    return _fit_rigid(object_points, corners_3d)


def detect_marker(
    rgb: np.ndarray,
    intrinsics: CameraIntrinsics,
    marker_id: int,
    marker_size_m: float,
    depth_m: np.ndarray | None = None,
) -> MarkerObservation | None:
    """Pose of marker ``marker_id`` (DICT_4X4_50) in the optical frame, or None if not seen.

    ``marker_size_m`` is the side of the black square. ``depth_m`` (metres along the optical
    axis, same size as ``rgb``) is optional; with it the distance comes from the depth image.
    """
    corners_px = find_marker_corners(rgb, marker_id)
    if corners_px is None:
        return None
    object_points = marker_object_points(marker_size_m)
    camera_matrix = intrinsics.matrix()
    candidates = _candidate_poses(object_points, corners_px, camera_matrix)
    if not candidates or candidates[0][2] > MAX_REPROJECTION_ERROR_PX:
        logger.warning(
            "marker %d found but no pose reprojects within %.1f px", marker_id, MAX_REPROJECTION_ERROR_PX
        )
        return None
    rvec, tvec, _ = candidates[0]
    rotation, translation = cv2.Rodrigues(rvec)[0], tvec
    refined = None if depth_m is None else _refine_with_depth(object_points, depth_m, corners_px, intrinsics)
    if refined is not None:
        rotation, translation = refined
    rvec_final = cv2.Rodrigues(rotation)[0]
    error = _reprojection_rms(object_points, corners_px, rvec_final, translation, camera_matrix)
    return MarkerObservation(
        marker_id=marker_id,
        T_optical_marker=make_transform(translation, rotation),
        reprojection_error_px=error,
        corners_px=corners_px,
        distance_m=float(np.linalg.norm(translation)),
        depth_refined=refined is not None,
        marker_size_m=marker_size_m,
    )


def draw_detection(
    rgb: np.ndarray, observation: MarkerObservation, intrinsics: CameraIntrinsics
) -> np.ndarray:
    """Copy of ``rgb`` with the marker outlined, its axes drawn (x red, y green, z blue) and labelled."""
    canvas = np.ascontiguousarray(rgb.copy())
    outline = np.round(observation.corners_px).astype(np.int32).reshape(-1, 1, 2)
    # 2 px in the exact colour (no anti-aliasing): a 1 px blended line kept as few as 5 pixels of its
    # colour around a small, oblique marker, too few to see (or for a test to find) in a saved frame
    cv2.polylines(canvas, [outline], isClosed=True, color=(255, 200, 0), thickness=2, lineType=cv2.LINE_8)
    rvec = cv2.Rodrigues(observation.T_optical_marker[:3, :3])[0]
    tvec = observation.T_optical_marker[:3, 3]
    # drawFrameAxes colours axes in BGR order; the canvas is RGB, so pass through a BGR view.
    bgr = cv2.cvtColor(canvas, cv2.COLOR_RGB2BGR)
    cv2.drawFrameAxes(bgr, intrinsics.matrix(), None, rvec, tvec, 0.75 * observation.marker_size_m, 2)
    canvas = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
    label = (
        f"id {observation.marker_id}  {observation.distance_m:.3f} m  "
        f"{observation.reprojection_error_px:.2f} px"
    )
    anchor = tuple(int(v) for v in np.round(observation.corners_px.min(axis=0) - [0, 6]))
    cv2.putText(canvas, label, anchor, cv2.FONT_HERSHEY_SIMPLEX, 0.4, (255, 0, 0), 1, cv2.LINE_AA)
    return canvas
