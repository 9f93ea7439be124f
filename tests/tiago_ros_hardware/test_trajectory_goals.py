"""A port trajectory as controller goals: the port's timing, sampled, split by controller (no ROS
graph needed: the goals are plain messages)."""

from __future__ import annotations

import pytest

from robot_port.trajectory_timing import profiled_path
from robot_port.types import JointTrajectory
from tiago_description import robot_model as rm
from tiago_description.joint_limits import velocity_limits
from tiago_ros_hardware.trajectory_goals import SAMPLE_PERIOD_S, controller_goals

LIMITS = velocity_limits()


def seconds(point) -> float:  # noqa: ANN001
    return point.time_from_start.sec + point.time_from_start.nanosec * 1e-9


def test_each_controller_gets_every_joint_of_its_own_and_the_ports_timing() -> None:
    start = {name: 0.0 for name in LIMITS} | {"torso_lift_joint": 0.1}
    waypoints = (
        {"arm_right_1_joint": 0.5, "torso_lift_joint": 0.2},
        {"arm_right_1_joint": 1.0, "torso_lift_joint": 0.25},
    )
    trajectory = JointTrajectory(waypoints, speed_scale=0.8, min_segment_s=0.1)
    goals, duration = controller_goals(trajectory, start, LIMITS)
    _names, path = profiled_path(start, waypoints, LIMITS, 0.8, 0.1)
    assert duration == pytest.approx(path.duration)
    assert set(goals) == {"arm_right", "torso"}
    arm = goals["arm_right"].trajectory
    assert list(arm.joint_names) == rm.controller_joints("arm_right")  # the whole arm: no partial goals
    times = [seconds(point) for point in arm.points]
    assert times[-1] == pytest.approx(duration, abs=1e-6)
    assert all(0 < b - a <= SAMPLE_PERIOD_S + 1e-9 for a, b in zip([0.0, *times], times, strict=False))
    last = arm.points[-1]
    assert last.positions[0] == pytest.approx(1.0) and all(v == pytest.approx(0.0) for v in last.velocities)
    assert all(list(point.positions[1:]) == [0.0] * 6 for point in arm.points)  # the joints not moved hold
    middle = arm.points[len(arm.points) // 2]
    expected, speeds = path.sample(seconds(middle))
    assert middle.positions[0] == pytest.approx(expected[0]) and middle.velocities[0] == pytest.approx(
        speeds[0]
    )
    assert seconds(goals["torso"].trajectory.points[-1]) == pytest.approx(duration, abs=1e-6)  # together
