"""What crosses the hardware port: joint groups, trajectories, camera frames, laser scans, poses.

Plain data with no behaviour beyond the arithmetic that defines it (a pinhole camera's projection),
so the skills and any implementation of the port agree on meaning without sharing code.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

Pose2D = tuple[float, float, float]
"""x (m), y (m) and heading (rad) of the base on the floor plane."""

ARM_SIDES = ("left", "right")
# The controllers a TIAGo++ moves its joints with, by the prefix of their joints' names (PAL's
# names: arm_left_1_joint, gripper_right_left_finger_joint, torso_lift_joint, head_1_joint).
JOINT_GROUPS = ("arm_left", "arm_right", "torso", "head", "gripper_left", "gripper_right")


def joint_group(joint_name: str) -> str:
    """The controller group that moves a joint; ValueError for a joint of no group."""
    for group in JOINT_GROUPS:
        if joint_name.startswith(group + "_"):
            return group
    raise ValueError(f"joint {joint_name!r} belongs to none of {', '.join(JOINT_GROUPS)}")


@dataclass(frozen=True)
class JointTrajectory:
    """Joint positions to pass through in order, all of the joints named in the first point.

    The timing is the controllers': every segment as fast as the joints' velocity limits scaled by
    ``speed_scale`` allow, and no shorter than ``min_segment_s``, under one trapezoidal speed
    profile that starts and ends at rest. Joints of several groups (an arm and the torso) start
    together and arrive together.
    """

    points: tuple[dict[str, float], ...]
    speed_scale: float = 1.0
    min_segment_s: float = 0.0
    name: str = "move_joints"

    @property
    def joint_names(self) -> tuple[str, ...]:
        return tuple(self.points[0]) if self.points else ()

    @property
    def groups(self) -> frozenset[str]:
        return frozenset(joint_group(name) for name in self.joint_names)


@dataclass(frozen=True)
class CameraIntrinsics:
    """Pinhole intrinsics in pixels plus the depth range in metres; defaults: TIAGo head camera."""

    width: int = 640
    height: int = 480
    fx: float = 522.2
    fy: float = 522.2
    cx: float = 319.5
    cy: float = 239.5
    near: float = 0.3
    far: float = 8.0

    def back_project(self, cols: np.ndarray, rows: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Pixels (column, row) at depths ``z`` as points in the optical frame, shape (N, 3)."""
        return np.column_stack([(cols - self.cx) / self.fx * z, (rows - self.cy) / self.fy * z, z])

    def matrix(self) -> np.ndarray:
        """3x3 camera matrix K, as OpenCV expects it."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def scaled(self, factor: int) -> CameraIntrinsics:
        """The same camera sampled ``factor`` times finer in each direction."""
        return replace(
            self,
            width=self.width * factor,
            height=self.height * factor,
            fx=self.fx * factor,
            fy=self.fy * factor,
            cx=(self.cx + 0.5) * factor - 0.5,
            cy=(self.cy + 0.5) * factor - 0.5,
        )


@dataclass(frozen=True)
class CameraFrame:
    """One head-camera frame with the robot's readings of the instant it was taken.

    ``joints`` and ``odometry`` belong to the image: the camera's pose follows from them by the
    robot model's forward kinematics, whatever moved since.
    """

    rgb: np.ndarray  # HxWx3 uint8
    depth: np.ndarray  # HxW float32, metres along the optical axis
    intrinsics: CameraIntrinsics
    joints: dict[str, float] = field(default_factory=dict)
    odometry: Pose2D = (0.0, 0.0, 0.0)
    stamp_s: float = 0.0


@dataclass(frozen=True)
class LaserScan:
    """One base-laser scan: ``ranges`` per beam (m; inf where nothing returned within
    ``range_max``), beams from ``angle_min`` every ``angle_increment`` (rad, counter-clockwise in
    the laser's frame), the laser's ``mount`` on the base, and the odometry of its instant."""

    ranges: np.ndarray
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    mount: Pose2D
    odometry: Pose2D
    stamp_s: float
