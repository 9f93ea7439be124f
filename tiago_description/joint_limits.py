"""Each joint's hardware velocity limit, from the robot model (the URDF the simulator builds its body from).

Why one reader: the limits a lab runs its robot with (`robot_limits`, which the simulator's controllers,
the ROS adapter and the time budget use) may not exceed these (rad/s; m/s for the torso and the fingers).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from functools import cache

from tiago_description import robot_model as rm


@cache
def velocity_limits() -> dict[str, float]:
    """Every moving joint's velocity limit; joints without a limit (the wheels) are left out."""
    limits = {}
    for joint in ET.fromstring(rm.build_urdf()).iter("joint"):
        limit = joint.find("limit")
        if limit is not None and limit.get("velocity"):
            limits[joint.get("name", "")] = float(limit.get("velocity", "0"))
    return limits
