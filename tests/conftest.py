"""Test-wide isolation: every pytest run gets its own ROS 2 domain and stays on this machine."""

from __future__ import annotations

import os

from ros_bridge.domain import reserve_domain_id
from ros_bridge.shared_memory import remove_dead_segments

# Set before anything imports rclpy, so every node of this run (and every child process, which
# inherits the environment) lives in a domain that no other run on this machine holds.
os.environ["ROS_DOMAIN_ID"] = str(reserve_domain_id())
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.setdefault("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")


def pytest_sessionfinish() -> None:
    """Shared memory that the run's killed ROS processes left behind goes with the run."""
    remove_dead_segments()
