"""On a real robot the adapter's time is the node's own clock; with a simulator it is /clock, and a
robot that publishes no clock is reported gone rather than read as time zero."""

from __future__ import annotations

import time

import pytest
import rclpy

from robot_port.hardware import HardwareUnavailable
from tiago_ros_hardware import hardware as ros_hardware
from tiago_ros_hardware.hardware import RosHardware


def test_the_robots_time_is_the_nodes_clock_or_the_simulators(monkeypatch: pytest.MonkeyPatch) -> None:
    if not rclpy.ok():
        rclpy.init()
    node = rclpy.create_node("test_robot_clock")
    try:
        assert RosHardware(node, simulated_clock=False).now() == pytest.approx(time.time(), abs=1.0)
        monkeypatch.setattr(ros_hardware, "READING_TIMEOUT_S", 0.2)
        with pytest.raises(HardwareUnavailable, match="/clock"):
            RosHardware(node).now()  # nothing publishes /clock in this test's ROS domain
    finally:
        node.destroy_node()
