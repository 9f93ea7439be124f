"""/tf as a TIAGo++ with Nav2 offers it: localisation's map -> odom correction.

Why: on a robot, AMCL sends the map -> odom transform on /tf (tf2_msgs/TFMessage), re-sent
regularly so that a listener that starts late still gets it; the ROS adapter reads localisation
from there (tiago_ros_hardware). The simulator's own /map_to_odom carries the same correction
without tf2_msgs, which only `./run` builds: this module is imported with the robot's interfaces
only. Lives on: the sim node's executor (the correction comes from the state publishers' timer).
"""

from __future__ import annotations

import threading

from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from tf2_msgs.msg import TFMessage

from robot_port.tiago_interfaces import TF

RESEND_PERIOD_S = 0.5  # AMCL re-sends its transform with every scan it matches; a standing robot's too


class MapToOdomBroadcast:
    """The latest map -> odom on /tf: at once when it changes, and every RESEND_PERIOD_S."""

    def __init__(self, node: Node) -> None:
        self.publisher = node.create_publisher(
            TFMessage, TF, QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
        )
        self._latest: TransformStamped | None = None
        self._lock = threading.Lock()
        node.create_timer(RESEND_PERIOD_S, self._resend)

    def update(self, correction: TransformStamped) -> None:
        with self._lock:
            self._latest = correction
        self.publisher.publish(TFMessage(transforms=[correction]))

    def _resend(self) -> None:
        with self._lock:
            latest = self._latest
        if latest is not None:
            self.publisher.publish(TFMessage(transforms=[latest]))
