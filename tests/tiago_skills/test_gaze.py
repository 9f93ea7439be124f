"""The head frames the marker and a held plate in one image (`tiago_skills.gaze`), on the robot model.

The geometry is random layout 211038's place into storage/1 as the robot saw it: the marker beside
the row's far right end, the held plate 0.54 m to its left above nest 1, the torso at the top. Aimed
at the midpoint of the marker's centre and the tool, the plate's outer end lay past the image's
corner (the full chain: test_held_plate_in_view.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lab_description.world import load_world
from robot_port.types import CameraIntrinsics
from tiago_description import transforms as tf
from tiago_description.kinematics import CAMERA_FRAME, RobotKinematics, head_angles_towards
from tiago_skills.gaze import head_angles_framing, held_plate_outline, marker_outline

WORLD = Path(__file__).parent / "fixtures" / "plate_beyond_the_image_corner.yaml"
CAMERA = CameraIntrinsics()
JOINTS = {"torso_lift_joint": 0.35}


def pixels(kinematics: RobotKinematics, aim: dict[str, float], points: np.ndarray) -> np.ndarray:
    """Where the head camera images the points (column, row), with the head at `aim`."""
    T_optical_base = tf.invert(kinematics.forward({**JOINTS, **aim}, CAMERA_FRAME))
    local = points @ T_optical_base[:3, :3].T + T_optical_base[:3, 3]
    return np.column_stack(
        [CAMERA.fx * local[:, 0] / local[:, 2] + CAMERA.cx, CAMERA.fy * local[:, 1] / local[:, 2] + CAMERA.cy]
    )


def inside(uv: np.ndarray) -> bool:
    return bool((uv[:, 0] >= 0).all() and (uv[:, 0] <= CAMERA.width - 1).all() and (uv[:, 1] >= 0).all()
                and (uv[:, 1] <= CAMERA.height - 1).all())  # fmt: skip


Scene = tuple[RobotKinematics, np.ndarray, np.ndarray, np.ndarray]


@pytest.fixture(scope="module")
def scene() -> Scene:
    """The robot model, the marker's and the plate's outlines in base_footprint, and the tool."""
    station = load_world(WORLD).station("storage")
    T_base_marker = tf.from_pose((0.5065, -0.5883, 0.9711), (0.50097, -0.50165, -0.5002, 0.49717))
    T_base_site = T_base_marker @ station.T_marker_site(1)
    tool = (T_base_site @ np.array([0.0028, 0.0004, 0.0808, 1.0]))[:3]
    marker = marker_outline(T_base_marker, station.marker_size)
    plate = held_plate_outline(T_base_site, tool, [(0.12776, 0.08548)])
    return RobotKinematics(), marker, plate, tool


def test_the_midpoint_aim_cuts_the_plate_off_and_the_framing_sees_both_whole(scene: Scene) -> None:
    kinematics, marker, plate, tool = scene
    both = np.vstack([marker, plate])
    midpoint = head_angles_towards(kinematics, JOINTS, (marker.mean(axis=0) + tool) / 2)
    assert not inside(pixels(kinematics, midpoint, plate)), "the fixture lost its point"
    aim, fits = head_angles_framing(kinematics, JOINTS, both, CAMERA)
    uv = pixels(kinematics, aim, both)
    assert fits and inside(uv)
    # centred: as much room on the left as on the right, above as below (within 2 px)
    left, right = uv[:, 0].min(), CAMERA.width - 1 - uv[:, 0].max()
    top, bottom = uv[:, 1].min(), CAMERA.height - 1 - uv[:, 1].max()
    assert abs(left - right) < 2.0 and abs(top - bottom) < 2.0, (left, right, top, bottom)


def test_outlines_that_cannot_fit_are_said_not_to(scene: Scene) -> None:
    kinematics, marker, plate, _tool = scene
    apart = np.vstack([marker, plate + np.array([0.0, 0.4, 0.0])])  # the plate 0.4 m further left
    _aim, fits = head_angles_framing(kinematics, JOINTS, apart, CAMERA)
    assert not fits
