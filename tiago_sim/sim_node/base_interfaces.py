"""The base's ROS 2 interfaces a TIAGo++ offers: its velocity command, Nav2's navigation goal, and the
docking a lab adds (Nav2's docking server, and the battery state its charging dock reads).

Why: software written against a real robot drives the base by
`/mobile_base_controller/cmd_vel_unstamped` (geometry_msgs/Twist, as twist_mux forwards it), navigates
by Nav2's `/navigate_to_pose` and asks its planner for a path by `/compute_path_to_pose`. The
simulator offers all three (tiago_twin --robot-interfaces): a velocity message drives the base for
CMD_VEL_TIMEOUT_S of robot time, as diff_drive_controller does, and a message before then renews the
command without braking; a navigation goal and a plan go to the navigation stand-in
(navigation.Navigation), the simulator's Nav2. The one dock of the world file answers to any dock
id of "" or its POI's name; docking drives onto it from where the base stands (or first navigates to
its POI, the staging pose, when the goal asks), undocking drives off it. `/battery_state` says
CHARGING while the charging contacts touch the dock, as Nav2's charging dock tells a docked robot.

Threads: subscription and goal callbacks on the node's executor threads; the base moves on the sim
thread (jobs).
"""

from __future__ import annotations

import logging
from typing import Any

from builtin_interfaces.msg import Duration
from geometry_msgs.msg import Twist
from nav2_msgs.action import ComputePathToPose, DockRobot, NavigateToPose, UndockRobot
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import BatteryState

from lab_description.world import World
from robot_port.tiago_interfaces import (
    BATTERY_STATE,
    CMD_VEL,
    COMPUTE_PATH_TO_POSE,
    DOCK_ROBOT,
    NAVIGATE_TO_POSE,
    UNDOCK_ROBOT,
)
from tiago_description import transforms as tf
from tiago_sim.sim_node.action_server import cancellable_server
from tiago_sim.sim_node.hardware import MotionExecution
from tiago_sim.sim_node.localisation_topics import stamp_of
from tiago_sim.sim_node.navigation import Navigation, path_message
from tiago_sim.sim_node.sim_thread import SimThread

log = logging.getLogger(__name__)

CMD_VEL_TIMEOUT_S = 0.5
"""Robot seconds a velocity command lasts without a new one (diff_drive_controller's default)."""
FEEDBACK_PERIOD_S = 0.2


def follow(handle: Any, execution: Any, each_period: Any = None) -> None:
    """Wait for `execution` (the port's Execution) to end, cancelling it when the goal `handle` is
    cancelled and calling `each_period` (feedback) between waits."""
    while not execution.wait(FEEDBACK_PERIOD_S):
        if handle.is_cancel_requested:
            execution.cancel()
        if each_period is not None:
            each_period()


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
        self.server = cancellable_server(node, NavigateToPose, NAVIGATE_TO_POSE, self._execute)

    def _execute(self, handle: Any) -> NavigateToPose.Result:
        goal = pose2d_of(handle.request.pose.pose)
        started = self.sim_thread.sim_time
        execution = self.navigation.navigate(goal, f"({goal[0]:.2f}, {goal[1]:.2f})")

        def feedback() -> None:
            message = NavigateToPose.Feedback()
            message.navigation_time = _duration(self.sim_thread.sim_time - started)
            message.estimated_time_remaining = _duration(execution.remaining_s)
            handle.publish_feedback(message)

        follow(handle, execution, feedback)
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


class ComputePathToPoseServer:
    """Nav2's /compute_path_to_pose on the navigation stand-in's planner: a path in the map frame
    from `start` (or the pose estimate), without driving it. No path: an empty one, aborted (the
    Humble action has no error code)."""

    def __init__(self, node: Node, navigation: Navigation, sim_thread: SimThread) -> None:
        self.navigation = navigation
        self.sim_thread = sim_thread
        self.server = cancellable_server(node, ComputePathToPose, COMPUTE_PATH_TO_POSE, self._execute)

    def _execute(self, handle: Any) -> ComputePathToPose.Result:
        request = handle.request
        if request.use_start:
            start = pose2d_of(request.start.pose)
        else:
            start = self.sim_thread.run(lambda sim: tuple(sim.pose_estimate()))
        poses = self.navigation.plan_path(start, pose2d_of(request.goal.pose))
        result = ComputePathToPose.Result()
        result.path = path_message(poses, stamp_of(self.sim_thread.sim_time))
        handle.succeed() if poses else handle.abort()
        return result


def pose2d_of(pose: Any) -> tuple[float, float, float]:
    """(x, y, yaw) of a geometry_msgs/Pose on the floor."""
    q = pose.orientation
    yaw = tf.yaw_of(tf.from_pose((0.0, 0.0, 0.0), (q.x, q.y, q.z, q.w)))
    return (float(pose.position.x), float(pose.position.y), yaw)


def _duration(seconds: float) -> Duration:
    stamp = stamp_of(max(seconds, 0.0))
    return Duration(sec=stamp.sec, nanosec=stamp.nanosec)


BATTERY_RATE_HZ = 5.0  # wall


class DockingServers:
    """/dock_robot and /undock_robot on the simulated dock, and /battery_state from its contacts."""

    def __init__(self, node: Node, world: World, navigation: Navigation, sim_thread: SimThread) -> None:
        self.world = world
        self.navigation = navigation
        self.sim_thread = sim_thread
        group = ReentrantCallbackGroup()
        self.servers = [
            cancellable_server(node, DockRobot, DOCK_ROBOT, self._dock, group),
            cancellable_server(node, UndockRobot, UNDOCK_ROBOT, self._undock, group),
        ]
        reliable = QoSProfile(depth=2, reliability=ReliabilityPolicy.RELIABLE)
        self.battery = node.create_publisher(BatteryState, BATTERY_STATE, reliable)
        node.create_timer(1.0 / BATTERY_RATE_HZ, self._publish_battery)

    def _publish_battery(self) -> None:
        try:
            sim_time, docked = self.sim_thread.run(lambda sim: (sim.sim_time, sim.is_docked()), 5.0)
        except Exception:  # noqa: BLE001 - the simulation is stopping
            return
        message = BatteryState(present=True, percentage=1.0)
        message.header.stamp = stamp_of(sim_time)
        message.power_supply_status = (
            BatteryState.POWER_SUPPLY_STATUS_CHARGING
            if docked
            else BatteryState.POWER_SUPPLY_STATUS_DISCHARGING
        )
        self.battery.publish(message)

    def _follow(self, handle: Any, start: Any) -> tuple[bool, str]:
        """Run a base motion started by `start(sim)` to its end (stopping it on a cancel)."""
        execution = MotionExecution(self.sim_thread.run(start, 60.0), self.sim_thread)
        follow(handle, execution)
        return execution.success, f"{execution.error_code}: {execution.message}"

    def _dock(self, handle: Any) -> DockRobot.Result:
        goal, result = handle.request, DockRobot.Result()
        if goal.use_dock_id and goal.dock_id not in ("", self.world.dock_poi):
            result.success, result.error_code = False, DockRobot.Result.DOCK_NOT_IN_DB
            result.error_msg = f"no dock {goal.dock_id!r}: the lab's dock is {self.world.dock_poi!r}"
            handle.abort()
            return result
        if goal.navigate_to_staging_pose:
            poi = self.world.pois[self.world.dock_poi]
            staging = self.navigation.navigate(
                (poi.x, poi.y, poi.yaw), f"the dock POI {self.world.dock_poi!r}"
            )
            follow(handle, staging)
            if not staging.success:
                result.success, result.error_code = False, DockRobot.Result.FAILED_TO_STAGE
                result.error_msg = staging.message
                handle.canceled() if handle.is_cancel_requested else handle.abort()
                return result
        docked, why = self._follow(handle, lambda sim: sim.dock())
        return self._ended(handle, result, docked, why)

    def _undock(self, handle: Any) -> UndockRobot.Result:
        undocked, why = self._follow(handle, lambda sim: sim.undock())
        return self._ended(handle, UndockRobot.Result(), undocked, why)

    @staticmethod
    def _ended(handle: Any, result: Any, success: bool, why: str) -> Any:
        result.success = success
        if success:
            handle.succeed()
            return result
        result.error_code, result.error_msg = type(result).FAILED_TO_CONTROL, why
        handle.canceled() if handle.is_cancel_requested else handle.abort()
        return result
