"""Test-wide isolation: every pytest run gets its own ROS 2 domain and stays on this machine."""

from __future__ import annotations

import os

from hypothesis import settings

from ros_bridge.domain import reserve_domain_id
from ros_bridge.shared_memory import remove_dead_segments

# Set before anything imports rclpy, so every node of this run (and every child process, which
# inherits the environment) lives in a domain that no other run on this machine holds.
os.environ["ROS_DOMAIN_ID"] = str(reserve_domain_id())
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.setdefault("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")

# No per-example deadline: speed is measured in benchmarks, and on a loaded machine one example of a
# 0.2 ms test took 451 ms (hypothesis's default deadline is 200 ms), failing a CI run.
settings.register_profile("sila_labware", deadline=None)
settings.load_profile("sila_labware")


def pytest_sessionfinish() -> None:
    """Shared memory that the run's killed ROS processes left behind goes with the run."""
    remove_dead_segments()
