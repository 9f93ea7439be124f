"""Joint moves as commands for `GoalRun.follow`: the one way the skills move joints to targets.

Why its own module: the behaviours, the final approach and the torso beside a drive all move joints
this way, and the drive's posture must not import the behaviours that use it. Pure; any thread.
"""

from __future__ import annotations

from collections.abc import Callable

from robot_port.execution import Execution
from robot_port.hardware import RobotHardware
from robot_port.types import JointTrajectory
from tiago_description.robot_limits import active_limits


def move_joints(targets: dict[str, float], speed_scale: float = 1.0) -> Callable[[RobotHardware], Execution]:
    """The command that moves joints to `targets` in one segment (for GoalRun.follow)."""
    return lambda hardware: hardware.follow_joint_trajectory(JointTrajectory((dict(targets),), speed_scale))


def move_s(start: dict[str, float], targets: dict[str, float]) -> float:
    """The slowest joint's time from `start` to `targets` at the robot's velocity limits (the ramps
    left out): how the skills compare two ways to the same tool pose."""
    velocity = active_limits().joint_velocity
    return max(
        (abs(value - start.get(name, value)) / velocity[name] for name, value in targets.items()), default=0.0
    )


def keyframe_points(joints: dict[str, float], frames: list[dict[str, float]]) -> tuple[dict[str, float], ...]:
    """A motion's keyframes (each naming only the joints it moves) as trajectory points that all name
    every joint the motion moves: a joint a keyframe leaves out holds where the one before put it."""
    names = list(dict.fromkeys(name for frame in frames for name in frame))
    held = {name: joints[name] for name in names}
    points = []
    for frame in frames:
        held = {**held, **frame}
        points.append(held)
    return tuple(points)
