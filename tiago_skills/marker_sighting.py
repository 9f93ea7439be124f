"""A marker's sighting from where the base stands, and whether the base still stands there (robot
software).

Why apart: the marker motion, its nest looks and its corrections all take their nest frames from one
sighting, reused while odometry says the base has not moved (the marker is fixed to its station, so
its pose in base_footprint holds whatever arms, torso and head do since).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from geometry_msgs.msg import Pose

from robot_port.types import CameraIntrinsics
from tiago_description import transforms as tf

# A cached marker stays valid while odometry moved less than this.
SAME_BASE_POSITION_M = 0.002
SAME_BASE_YAW_RAD = 0.003


@dataclass(frozen=True)
class MarkerSighting:
    station: str
    T_base_marker: np.ndarray
    odometry: tuple[float, float, float]
    reprojection_error_px: float
    joints: dict[str, float] = field(default_factory=dict)  # readings taken with the image
    intrinsics: CameraIntrinsics = field(default_factory=CameraIntrinsics)  # the image's camera


def same_place(then: tuple[float, float, float], now: tuple[float, float, float]) -> bool:
    """Whether the base stands where odometry put it `then` (a sighting from there still holds)."""
    moved = math.hypot(now[0] - then[0], now[1] - then[1])
    return (
        moved < SAME_BASE_POSITION_M and abs(math.remainder(now[2] - then[2], math.tau)) < SAME_BASE_YAW_RAD
    )


def pose_msg(transform: np.ndarray) -> Pose:
    position, quat = tf.to_pose(transform)
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = (float(v) for v in position)
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = (float(v) for v in quat)
    return pose
