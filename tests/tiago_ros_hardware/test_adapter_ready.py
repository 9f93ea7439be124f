"""The ROS adapter's start-up check: with no robot answering, it names what is missing instead of
sending goals that nobody receives (a real rclpy node over DDS, in the test's own ROS domain)."""

from __future__ import annotations

import pytest
import rclpy

from robot_port.hardware import HardwareUnavailable
from tiago_ros_hardware.hardware import RosHardware


def test_with_no_robot_the_adapter_names_a_missing_action_server() -> None:
    if not rclpy.ok():
        rclpy.init()
    node = rclpy.create_node("test_adapter_ready")
    try:
        hardware = RosHardware(node)
        with pytest.raises(
            HardwareUnavailable, match=r"no action server /arm_left_controller/follow_joint_trajectory"
        ):
            hardware.wait_until_ready(timeout_s=0.5)
    finally:
        node.destroy_node()
