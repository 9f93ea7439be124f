"""Where the head looks to see several things whole in one image (robot software).

Why: the place correction measures the held plate against the station's marker in one image, the
only way the camera's calibration errors cancel between them. Aimed at the midpoint of the marker's
centre and the tool, with the marker at a row's far end 0.59 m right of the base and the plate held
0.54 m to its left, 0.95 m high, the plate's outer end lay past the image's corner: the plate, near
the camera, spans far more of the image than the marker. Nothing was measured, and the place went
down uncorrected beside the nest. The head is now turned until the outlines' extent is centred in
the image, and the caller learns whether everything fits. Where marker and plate cannot fit in one
image (a marker 0.5 m or more beside the nest, seen from near), the plate is framed alone and measured
against the nest the first image's marker gave: the camera's error then changes with the head's turn
between the two images (about a millimetre at the nest per 0.1 rad, against 8 to 11 mm unmeasured).

Pure computation on the robot model; safe on any thread that owns its own `RobotKinematics`.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from lab_description.world import World
from robot_port.types import CameraIntrinsics
from tiago_description import transforms as tf
from tiago_description.kinematics import (
    CAMERA_FRAME,
    RobotKinematics,
    head_angles_towards,
    within_head_limits,
)
from tiago_skills.marker_sighting import MarkerSighting

MARKER_QUIET_ZONE = 0.6
"""Half the marker's side times this is kept in the image around its centre: the square and the
white border the detector needs."""
PLATE_WINDOW_M = 0.02
"""Kept in the image around a held plate's outline: the measurement reads pixels this far beyond it
(`perception.held_plate.locate_held_plate`, ``window_m``)."""
FRAMING_ITERATIONS = 4


def marker_outline(T_base_marker: np.ndarray, size: float) -> np.ndarray:
    """The marker's square with its quiet zone: four corners in base_footprint, shape (4, 3)."""
    half = size * MARKER_QUIET_ZONE
    corners = [(sx * half, sy * half, 0.0, 1.0) for sx in (-1, 1) for sy in (-1, 1)]
    return (T_base_marker @ np.array(corners).T).T[:, :3]


def held_plate_outline(
    T_base_site: np.ndarray, tool_in_base: np.ndarray, sizes: Iterable[tuple[float, float]]
) -> np.ndarray:
    """The largest plate type's outline about the tool, square to the nest, with the measurement's
    window: four corners in base_footprint at the tool's height, shape (4, 3)."""
    length = max(size[0] for size in sizes) / 2 + PLATE_WINDOW_M
    width = max(size[1] for size in sizes) / 2 + PLATE_WINDOW_M
    tool_in_site = tf.invert(T_base_site) @ np.append(tool_in_base, 1.0)
    x, y, z = tool_in_site[:3]
    corners = [(x + sx * length, y + sy * width, z, 1.0) for sx in (-1, 1) for sy in (-1, 1)]
    return (T_base_site @ np.array(corners).T).T[:, :3]


def head_angles_framing(
    kinematics: RobotKinematics,
    joints: dict[str, float],
    points: np.ndarray,
    intrinsics: CameraIntrinsics,
) -> tuple[dict[str, float], bool]:
    """Pan and tilt that centre the extent of `points` (base_footprint, shape (N, 3)) in the head
    camera's image, and whether every point then lies inside it. Limits are the caller's
    (`kinematics.within_head_limits`)."""
    aim = head_angles_towards(kinematics, joints, points.mean(axis=0))
    for _ in range(FRAMING_ITERATIONS):
        x, y = _image_angles(kinematics, {**joints, **aim}, points)
        aim = {
            "head_1_joint": aim["head_1_joint"] - (x.min() + x.max()) / 2,  # x right: pan left is +
            "head_2_joint": aim["head_2_joint"] - (y.min() + y.max()) / 2,  # y down: tilt down is -
        }
    x, y = _image_angles(kinematics, {**joints, **aim}, points)
    half_width = np.arctan2(intrinsics.width / 2, intrinsics.fx)
    half_height = np.arctan2(intrinsics.height / 2, intrinsics.fy)
    fits = bool(np.abs(x).max() <= half_width and np.abs(y).max() <= half_height)
    return aim, fits


def _image_angles(
    kinematics: RobotKinematics, joints: dict[str, float], points: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each point's angle right of and below the optical axis (rad)."""
    T_base_optical = kinematics.forward(joints, CAMERA_FRAME)
    local = (points - T_base_optical[:3, 3]) @ T_base_optical[:3, :3]  # rows: R^T (p - t)
    return np.arctan2(local[:, 0], local[:, 2]), np.arctan2(local[:, 1], local[:, 2])


def marker_and_held_plate(
    kinematics: RobotKinematics,
    joints: dict[str, float],
    sighting: MarkerSighting,
    world: World,
    T_base_site: np.ndarray,
    tool_in_base: np.ndarray,
    *,
    with_marker: bool = True,
) -> tuple[dict[str, float], bool]:
    """The head's aim (within its limits) that frames the sighting's marker and the plate held by the
    tool over the site together, and whether both then fit in the image. Without the marker
    (`with_marker` False): the plate alone, the look of last resort where the two do not fit."""
    points = _plate_outline(world, T_base_site, tool_in_base)
    if with_marker:
        marker = marker_outline(sighting.T_base_marker, world.station(sighting.station).marker_size)
        points = np.vstack([marker, points])
    return _framed(kinematics, joints, points, sighting.intrinsics)


def _plate_outline(world: World, T_base_site: np.ndarray, tool_in_base: np.ndarray) -> np.ndarray:
    sizes = [(labware.length, labware.width) for labware in world.labware_types.values()]
    return held_plate_outline(T_base_site, tool_in_base, sizes)


def _framed(
    kinematics: RobotKinematics, joints: dict[str, float], points: np.ndarray, intrinsics: CameraIntrinsics
) -> tuple[dict[str, float], bool]:
    aim, fits = head_angles_framing(kinematics, joints, points, intrinsics)
    limited = within_head_limits(aim)
    return limited, fits and all(abs(limited[name] - aim[name]) < 1e-9 for name in aim)
