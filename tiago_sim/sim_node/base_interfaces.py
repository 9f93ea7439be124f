"""The base's ROS 2 interfaces a TIAGo++ offers: its velocity command and Nav2's navigation goal.

Why: software written against a real robot drives the base by `/mobile_base_controller/cmd_vel_unstamped`
(geometry_msgs/Twist, as twist_mux forwards it) and navigates by Nav2's `/navigate_to_pose`. The
simulator offers both (tiago_twin --robot-interfaces): a velocity message drives the base for
CMD_VEL_TIMEOUT_S of robot time, as diff_drive_controller does, and a message before then renews the
command without braking; a navigation goal goes to the navigation stand-in (navigation.Navigation),
the simulator's Nav2.

Threads: subscription and goal callbacks on the node's executor threads; the base moves on the sim
thread (jobs).
"""

from __future__ import annotations

import logging
import math
from typing import Any

from builtin_interfaces.msg import Duration
from geometry_msgs.msg import Twist
from nav2_msgs.action import NavigateToPose
from rclpy.action import ActionServer, CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy

from robot_port.tiago_interfaces import CMD_VEL, NAVIGATE_TO_POSE
from tiago_sim.sim_node.localisation_topics import stamp_of
from tiago_sim.sim_node.navigation import Navigation
from tiago_sim.sim_node.sim_thread import SimThread

log = logging.getLogger(__name__)

CMD_VEL_TIMEOUT_S = 0.5
"""Robot seconds a velocity command lasts without a new one (diff_drive_controller's default)."""
FEEDBACK_PERIOD_S = 0.2


class BaseVelocityInput:
    """/mobile_base_controller/cmd_vel_unstamped: each message drives the base for CMD_VEL_TIMEOUT_S."""

    def __init__(self, node: Node, sim_thread: SimThread) -> None:
        self.sim_thread = sim_thread
        self._motion: Any = None  # the running VelocityMotion (read and written on the sim thread)
        self._refused = ""
        qos = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)
        node.create_subscription(Twist, CMD_VEL, self._on_twist, qos)

    def _on_twist(self, twist: Twist) -> None:
        linear, angular = float(twist.linear.x), float(twist.angular.z)
        self.sim_thread.call(lambda sim: self._drive(sim, linear, angular))

    def _drive(self, sim: Any, linear: float, angular: float) -> None:
        motion = self._motion
        if motion is not None and motion.renew(linear, angular, CMD_VEL_TIMEOUT_S):
            return
        motion = sim.command_velocity(linear, angular, CMD_VEL_TIMEOUT_S)
        if motion.done and not motion.success:  # the base is busy with another command, or docked
            if motion.message != self._refused:
                log.warning("%s: velocity command refused: %s", CMD_VEL, motion.message)
            self._refused = motion.message
            return
        self._refused, self._motion = "", motion


class NavigateToPoseServer:
    """Nav2's /navigate_to_pose on the navigation stand-in: the goal pose is in the map frame."""

    def __init__(self, node: Node, navigation: Navigation, sim_thread: SimThread) -> None:
        self.navigation = navigation
        self.sim_thread = sim_thread
        self.server = ActionServer(
            node,
            NavigateToPose,
            NAVIGATE_TO_POSE,
            execute_callback=self._execute,
            cancel_callback=lambda _handle: CancelResponse.ACCEPT,
            callback_group=ReentrantCallbackGroup(),
        )

    def _execute(self, handle: Any) -> NavigateToPose.Result:
        pose = handle.request.pose.pose
        q = pose.orientation
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        goal = (float(pose.position.x), float(pose.position.y), yaw)
        started = self.sim_thread.sim_time
        execution = self.navigation.navigate(goal, f"({goal[0]:.2f}, {goal[1]:.2f})")
        while not execution.wait(FEEDBACK_PERIOD_S):
            if handle.is_cancel_requested:
                execution.cancel()
            feedback = NavigateToPose.Feedback()
            feedback.navigation_time = _duration(self.sim_thread.sim_time - started)
            feedback.estimated_time_remaining = _duration(execution.remaining_s)
            handle.publish_feedback(feedback)
        if execution.success:
            handle.succeed()
        elif handle.is_cancel_requested:
            handle.canceled()
        else:
            log.info(
                "%s: navigation failed: %s %s", NAVIGATE_TO_POSE, execution.error_code, execution.message
            )
            handle.abort()
        return NavigateToPose.Result()


def _duration(seconds: float) -> Duration:
    stamp = stamp_of(max(seconds, 0.0))
    return Duration(sec=stamp.sec, nanosec=stamp.nanosec)
