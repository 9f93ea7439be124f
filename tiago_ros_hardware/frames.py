"""The robot's transforms the adapter reads: localisation's map -> odom from `/tf`, and the robot's
fixed frames from `/tf_static` (the laser's mount).

Why apart: on a TIAGo++, AMCL sends map -> odom on /tf, and robot_state_publisher latches the URDF's
fixed joints on /tf_static; the adapter needs one transform of the first and a sensor's mount from
the second, not a tf2 buffer (no tf2 wheel on the package index). Threads: the callbacks on the
node's executor, `mount` on any thread.
"""

from __future__ import annotations

import math
import threading
from typing import Any

from tf2_msgs.msg import TFMessage

from robot_port.hardware import HardwareUnavailable
from robot_port.tiago_interfaces import TF_STATIC
from robot_port.types import Pose2D
from tiago_description import transforms as tf
from tiago_description.fixed_frames import FixedFrame, chain

MAP_FRAME, ODOM_FRAME, BASE_FRAME = "map", "odom", "base_footprint"


def yaw_of(orientation: Any) -> float:
    """The heading of a geometry_msgs/Quaternion (its rotation about z)."""
    q = orientation
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class RobotFrames:
    """The latest map -> odom correction, and the fixed frames heard so far."""

    def __init__(self, timeout_s: float) -> None:
        self.timeout_s = timeout_s
        self.correction: Pose2D = (0.0, 0.0, 0.0)
        self._fixed: dict[str, FixedFrame] = {}  # by child frame
        self._fixed_changed = threading.Condition()

    def on_tf(self, message: TFMessage) -> None:
        """Localisation's map -> odom (the other transforms on /tf are not needed)."""
        for stamped in message.transforms:
            if (stamped.header.frame_id, stamped.child_frame_id) == (MAP_FRAME, ODOM_FRAME):
                t = stamped.transform
                self.correction = (float(t.translation.x), float(t.translation.y), yaw_of(t.rotation))

    def on_tf_static(self, message: TFMessage) -> None:
        """The robot's fixed frames (robot_state_publisher sends them once, latched)."""
        with self._fixed_changed:
            for stamped in message.transforms:
                t = stamped.transform
                transform = tf.from_pose(
                    (t.translation.x, t.translation.y, t.translation.z),
                    (t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w),
                )
                self._fixed[stamped.child_frame_id] = FixedFrame(
                    stamped.header.frame_id, stamped.child_frame_id, transform
                )
            self._fixed_changed.notify_all()

    def mount(self, frame: str) -> Pose2D:
        """Where `frame` sits on the base (x, y, yaw in base_footprint); waits for /tf_static."""
        with self._fixed_changed:
            found = self._fixed_changed.wait_for(
                lambda: chain(self._fixed, BASE_FRAME, frame) is not None, self.timeout_s
            )
            if not found:
                raise HardwareUnavailable(f"no fixed frames from {BASE_FRAME} to {frame} on {TF_STATIC}")
            transform = chain(self._fixed, BASE_FRAME, frame)
        assert transform is not None
        return float(transform[0, 3]), float(transform[1, 3]), tf.yaw_of(transform)
