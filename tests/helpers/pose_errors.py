"""How far the robot's believed pose and its raw odometry are from the simulator's truth, over ROS.

Why from topics: the long runs talk to a `serve` in another process; the sim node publishes the
believed pose (/robot_state base_pose, the localised estimate), raw odometry
(/mobile_base_controller/odom) and, like Gazebo's ground-truth plugins, the true pose
(/ground_truth/base_pose), all from one snapshot. The truth is read here only to measure.
"""

from __future__ import annotations

import math
import threading
import time
from typing import Any

from geometry_msgs.msg import Pose2D
from labware_interfaces.msg import RobotState
from nav_msgs.msg import Odometry
from rclpy.qos import QoSProfile, ReliabilityPolicy

from ros_bridge.runtime import RosRuntime


def _planar_error(pose: tuple[float, float, float], truth: tuple[float, float, float]) -> tuple[float, float]:
    """Position error in cm and heading error in degrees."""
    position = 100.0 * math.hypot(pose[0] - truth[0], pose[1] - truth[1])
    return position, math.degrees(abs(math.remainder(pose[2] - truth[2], math.tau)))


class PoseErrorProbe:
    """Latest believed, odometry and true base poses; ``sample`` compares them."""

    def __init__(self, runtime: RosRuntime) -> None:
        self._lock = threading.Lock()
        self._latest: dict[str, tuple[float, float, float]] = {}
        qos = QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE)

        def keep(name: str, pose: tuple[float, float, float]) -> None:
            with self._lock:
                self._latest[name] = pose

        def odometry(message: Odometry) -> None:
            q = message.pose.pose.orientation
            yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
            keep("odometry", (message.pose.pose.position.x, message.pose.pose.position.y, yaw))

        def subscribe() -> list[Any]:
            node = runtime.node
            return [
                node.create_subscription(
                    Pose2D, "/ground_truth/base_pose", lambda m: keep("truth", (m.x, m.y, m.theta)), qos
                ),
                node.create_subscription(
                    RobotState,
                    "/robot_state",
                    lambda m: keep("believed", (m.base_pose.x, m.base_pose.y, m.base_pose.theta)),
                    qos,
                ),
                node.create_subscription(Odometry, "/mobile_base_controller/odom", odometry, qos),
            ]

        self.subscriptions = runtime.call(subscribe)

    def sample(self, settle_s: float = 1.5) -> dict[str, float]:
        """After the base has stood ``settle_s``: localised and odometry errors (cm, deg)."""
        time.sleep(settle_s)
        with self._lock:
            latest = dict(self._latest)
        if {"truth", "believed", "odometry"} - set(latest):
            return {}
        localised = _planar_error(latest["believed"], latest["truth"])
        odometry = _planar_error(latest["odometry"], latest["truth"])
        return {
            "localised_cm": round(localised[0], 2),
            "localised_deg": round(localised[1], 3),
            "odometry_cm": round(odometry[0], 2),
            "odometry_deg": round(odometry[1], 3),
        }
