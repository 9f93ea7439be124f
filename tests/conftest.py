"""Test-wide isolation: every pytest run gets its own ROS 2 domain and stays on this machine."""

from __future__ import annotations

import os
import random

# Set before anything imports rclpy, so every node of this run (and every child process,
# which inherits the environment) lives in a domain no parallel run uses.
os.environ["ROS_DOMAIN_ID"] = str(random.SystemRandom().randint(1, 101))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.setdefault("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")
