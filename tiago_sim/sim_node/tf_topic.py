"""/tf and /tf_static as a TIAGo++ with Nav2 offers them: localisation's map -> odom correction, and
the robot model's fixed frames.

Why: on a robot, AMCL sends the map -> odom transform on /tf (tf2_msgs/TFMessage), re-sent
regularly so that a listener that starts late still gets it; the ROS adapter reads localisation
from there (tiago_ros_hardware). robot_state_publisher sends the URDF's fixed joints once on
/tf_static, latched (transient local) so that a late listener gets them too; the adapter reads the
laser's mount there. The simulator's own /map_to_odom carries the same correction
without tf2_msgs, which only `./run` builds: this module is imported with the robot's interfaces
only. Lives on: the sim node's executor (the correction comes from the state publishers' timer).
"""

from __future__ import annotations

import threading

from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from tf2_msgs.msg import TFMessage

from robot_port.tiago_interfaces import TF, TF_STATIC
from tiago_description.fixed_frames import FixedFrame
from tiago_description.transforms import to_pose

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


def static_transforms(node: Node, frames: tuple[FixedFrame, ...]) -> None:
    """Send `frames` once on /tf_static, latched, stamped with the node's clock now."""
    latched = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
    )
    publisher = node.create_publisher(TFMessage, TF_STATIC, latched)
    stamp = node.get_clock().now().to_msg()
    transforms = []
    for frame in frames:
        position, quaternion = to_pose(frame.transform)
        message = TransformStamped()
        message.header.stamp = stamp
        message.header.frame_id, message.child_frame_id = frame.parent, frame.child
        translation, rotation = message.transform.translation, message.transform.rotation
        translation.x, translation.y, translation.z = (float(value) for value in position)
        rotation.x, rotation.y, rotation.z, rotation.w = (float(value) for value in quaternion)
        transforms.append(message)
    publisher.publish(TFMessage(transforms=transforms))
