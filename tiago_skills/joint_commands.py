"""Joint moves as commands for `GoalRun.follow`: the one way the skills move joints to targets.

Why its own module: the behaviours, the final approach and the torso beside a drive all move joints
this way, and the drive's posture must not import the behaviours that use it. Pure; any thread.
"""

from __future__ import annotations

from collections.abc import Callable

from robot_port.execution import Execution
from robot_port.hardware import RobotHardware
from robot_port.types import JointTrajectory


def move_joints(targets: dict[str, float], speed_scale: float = 1.0) -> Callable[[RobotHardware], Execution]:
    """The command that moves joints to `targets` in one segment (for GoalRun.follow)."""
    return lambda hardware: hardware.follow_joint_trajectory(JointTrajectory((dict(targets),), speed_scale))
