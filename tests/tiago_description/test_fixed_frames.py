"""The robot model's fixed frames, as /tf_static carries them: the sensors' mounts where the
simulation puts the sensors."""

from __future__ import annotations

import numpy as np
import pytest

from tiago_description import robot_model as rm
from tiago_description import transforms as tf
from tiago_description.fixed_frames import chain, fixed_frames
from tiago_description.kinematics import CAMERA_FRAME, RobotKinematics


def frames_by_child() -> dict:
    return {frame.child: frame for frame in fixed_frames(rm.build_urdf())}


def test_the_laser_frame_sits_at_the_lasers_mount() -> None:
    laser = chain(frames_by_child(), "base_footprint", "base_laser_link")
    assert laser is not None
    x, y, yaw = rm.LASER_MOUNT
    assert laser[:3, 3] == pytest.approx([x, y, rm.LASER_HEIGHT])
    assert tf.yaw_of(laser) == pytest.approx(yaw)


@pytest.mark.parametrize("frame", [CAMERA_FRAME, "hotel_slot_1", "gripper_right_grasping_frame"])
def test_fixed_frames_agree_with_the_kinematics_model(frame: str) -> None:
    """Read from the URDF text as robot_state_publisher would, each frame sits on its moving parent
    where the kinematics model (pinocchio, on the same URDF) puts it."""
    frames = frames_by_child()
    parent = frame
    while parent in frames:  # up to the first link that a moving joint carries
        parent = frames[parent].parent
    kinematics = RobotKinematics()
    joints = {"head_1_joint": 0.3, "head_2_joint": -0.5, "arm_right_4_joint": 1.0, "torso_lift_joint": 0.2}
    fixed = chain(frames, parent, frame)
    assert fixed is not None
    expected = kinematics.forward(joints, frame)
    via_parent = kinematics.forward(joints, parent) @ fixed
    assert np.allclose(via_parent, expected, atol=1e-9)


def test_frames_that_do_not_join_have_no_chain() -> None:
    assert chain(frames_by_child(), "base_footprint", "arm_right_tool_link") is None  # a moving joint between
    assert chain(frames_by_child(), "base_footprint", "no_such_frame") is None
