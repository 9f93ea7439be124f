"""Topics of the base laser and localisation: /scan, /amcl_pose, /map_to_odom.

Why these names and types: they are what a TIAGo++ running the ROS 2 navigation stack offers and
RViz shows: sensor_msgs/LaserScan on /scan in frame ``base_laser_link``, and AMCL's
geometry_msgs/PoseWithCovarianceStamped on /amcl_pose in frame ``map`` (durable: a late
subscriber gets the last pose). The map -> odom correction, which the navigation stack sends on
/tf, goes out as geometry_msgs/TransformStamped on /map_to_odom: tf2_msgs is not among the ROS
packages installed here, so there is no /tf; the laser's mount on base_footprint is fixed and
documented (physics.base_laser.LaserSpec) instead of sent on /tf_static.
Lives on: the rclpy executor thread of the state publishers' timer.
"""

from __future__ import annotations

import array
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import PoseWithCovarianceStamped, TransformStamped
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import LaserScan

from robot_port.tiago_interfaces import LASER
from tiago_sim.physics.base_laser import LASER_FRAME, LaserReading
from tiago_sim.sim_node.localisation import Localised

SCAN_TOPIC = LASER
POSE_TOPIC = "/amcl_pose"
CORRECTION_TOPIC = "/map_to_odom"
MAP_FRAME = "map"
ODOM_FRAME = "odom"


@dataclass(frozen=True)
class LocalisationView:
    """The latest scan and localisation update, read together on the sim thread."""

    scan: LaserReading | None
    localised: Localised | None


def stamp_of(sim_time: float) -> Time:
    """A ROS time stamp of simulated time (every sim node topic is stamped with it)."""
    seconds = math.floor(sim_time)
    return Time(sec=int(seconds), nanosec=int((sim_time - seconds) * 1e9))


def scan_message(reading: LaserReading) -> LaserScan:
    spec = reading.spec
    message = LaserScan()
    message.header.stamp = stamp_of(reading.sim_time)
    message.header.frame_id = LASER_FRAME
    message.angle_min, message.angle_max = float(spec.angle_min), float(spec.angles()[-1])
    message.angle_increment = float(spec.angle_increment)
    message.time_increment = 0.0  # the simulated scan is taken at one instant
    message.scan_time = 1.0 / spec.rate_hz
    message.range_min, message.range_max = float(spec.range_min), float(spec.range_max)
    message.ranges = array.array("f", reading.ranges.astype(np.float32).tobytes())
    return message


def pose_message(localised: Localised) -> PoseWithCovarianceStamped:
    x, y, yaw = localised.update.pose
    message = PoseWithCovarianceStamped()
    message.header.stamp = stamp_of(localised.sim_time)
    message.header.frame_id = MAP_FRAME
    pose = message.pose.pose
    pose.position.x, pose.position.y = float(x), float(y)
    pose.orientation.z, pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    covariance = np.zeros((6, 6))
    planar = [0, 1, 5]  # x, y and the rotation about z, in ROS's (x, y, z, roll, pitch, yaw) order
    covariance[np.ix_(planar, planar)] = localised.update.covariance
    message.pose.covariance = [float(v) for v in covariance.ravel()]
    return message


def correction_message(localised: Localised) -> TransformStamped:
    x, y, yaw = localised.update.map_from_odom
    message = TransformStamped()
    message.header.stamp = stamp_of(localised.sim_time)
    message.header.frame_id, message.child_frame_id = MAP_FRAME, ODOM_FRAME
    message.transform.translation.x, message.transform.translation.y = float(x), float(y)
    message.transform.rotation.z, message.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return message


class LocalisationTopics:
    """Publishes each new scan and each new localisation update once."""

    def __init__(self, node: Node) -> None:
        reliable = QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE)
        latched = QoSProfile(
            depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
        )
        self.scan_pub = node.create_publisher(LaserScan, SCAN_TOPIC, reliable)
        self.pose_pub = node.create_publisher(PoseWithCovarianceStamped, POSE_TOPIC, latched)
        self.correction_pub = node.create_publisher(TransformStamped, CORRECTION_TOPIC, latched)
        self._scan: LaserReading | None = None
        self._localised: Localised | None = None
        # Also told each new correction: the robot's own /tf, when the simulator serves it (tf_topic).
        self.correction_listeners: list[Callable[[TransformStamped], None]] = []

    def scans_wanted(self) -> bool:
        return self.scan_pub.get_subscription_count() > 0

    def publish(self, view: LocalisationView) -> None:
        if view.scan is not None and view.scan is not self._scan:
            self._scan = view.scan
            self.scan_pub.publish(scan_message(view.scan))
        if view.localised is not None and view.localised is not self._localised:
            self._localised = view.localised
            self.pose_pub.publish(pose_message(view.localised))
            correction = correction_message(view.localised)
            self.correction_pub.publish(correction)
            for listener in self.correction_listeners:
                listener(correction)
