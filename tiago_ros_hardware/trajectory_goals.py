"""A port JointTrajectory (robot_port.types) as FollowJointTrajectory goals, one per controller.

Why sampled: a robot's joint trajectory controller takes points with their times, where the port's
trajectory leaves the timing to the controller (robot_port.trajectory_timing). The adapter times
the path by the port's rule and samples it every SAMPLE_PERIOD_S, with each sample's velocities, so
that the controller's spline runs the same motion in the same time as the simulator's own
controller would. A controller's joints that the trajectory does not move hold where they stand
(the controllers take no partial goals). Pure; any thread.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from builtin_interfaces.msg import Duration
from control_msgs.action import FollowJointTrajectory
from trajectory_msgs.msg import JointTrajectoryPoint

from robot_port.trajectory_timing import profiled_path
from robot_port.types import JointTrajectory, joint_group
from tiago_description.robot_model import controller_joints

SAMPLE_PERIOD_S = 0.05
"""Seconds of robot time between the points sent (the controller splines between them)."""


def duration_msg(seconds: float) -> Duration:
    whole = math.floor(seconds)
    return Duration(sec=int(whole), nanosec=int(round((seconds - whole) * 1e9)) % 1_000_000_000)


def controller_goals(
    trajectory: JointTrajectory, start: Mapping[str, float], velocity_limits: Mapping[str, float]
) -> tuple[dict[str, FollowJointTrajectory.Goal], float]:
    """One goal per joint group the trajectory moves, and the trajectory's duration (s)."""
    names, path = profiled_path(
        start, trajectory.points, velocity_limits, trajectory.speed_scale, trajectory.min_segment_s
    )
    count = max(1, math.ceil(path.duration / SAMPLE_PERIOD_S))
    times = [path.duration * (index + 1) / count for index in range(count)]
    samples = [path.sample(t) for t in times]
    index_of = {name: i for i, name in enumerate(names)}
    goals: dict[str, FollowJointTrajectory.Goal] = {}
    for group in sorted({joint_group(name) for name in names}):
        joints = controller_joints(group)
        goal = FollowJointTrajectory.Goal()
        goal.trajectory.joint_names = joints
        for at, (positions, velocities) in zip(times, samples, strict=True):
            point = JointTrajectoryPoint(time_from_start=duration_msg(at))
            point.positions = [_value(positions, index_of, start, joint) for joint in joints]
            point.velocities = [_value(velocities, index_of, None, joint) for joint in joints]
            goal.trajectory.points.append(point)
        goals[group] = goal
    return goals, path.duration


def _value(
    values: np.ndarray, index_of: Mapping[str, int], held: Mapping[str, float] | None, joint: str
) -> float:
    """A sampled joint's value; a joint the trajectory leaves alone holds its start (velocity 0)."""
    if joint in index_of:
        return float(values[index_of[joint]])
    return float(held[joint]) if held is not None else 0.0
