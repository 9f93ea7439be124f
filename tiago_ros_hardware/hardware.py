"""RosHardware: robot_port.RobotHardware over a TIAGo++'s own ROS 2 interfaces.

Readings come from the robot's topics (topics.TopicHistory): a reading waits for a message stamped
at or after the robot's time of the call, so it shows the robot as it stands then. Commands are
goals to the robot's controllers and to Nav2 (executions.GoalsExecution; a plan waits for Nav2's
planner, nav2_goals), or loops the adapter
closes itself over the velocity command and odometry (executions.LoopExecution): the port's
short straight drive has no standard interface on a robot.

Where a TIAGo++ has no sensor for what the port offers, the adapter derives it: holding, from the
fingers' joint positions after closing (they stop apart on a plate). Docking is Nav2's docking
server (`dock_id` names the lab's dock; "" for its only one); docked is the battery charging.

Names and types: robot_port.tiago_interfaces. Localisation's correction is AMCL's map -> odom on
`/tf`; the laser's mount comes from the fixed frames robot_state_publisher latches on `/tf_static`.

Threads: the node's callbacks on its executor's threads (the caller spins the node, with threads to
spare for the goals' answers); every port method on any thread.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
from control_msgs.action import FollowJointTrajectory
from geometry_msgs.msg import Twist
from nav2_msgs.action import ComputePathToPose, DockRobot, NavigateToPose, UndockRobot
from nav_msgs.msg import Odometry
from play_motion2_msgs.action import PlayMotion2
from rclpy.action import ActionClient
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import BatteryState, CameraInfo, Image, JointState
from sensor_msgs.msg import LaserScan as LaserScanMsg
from tf2_msgs.msg import TFMessage
from trajectory_msgs.msg import JointTrajectoryPoint

from robot_port.action_client import ThreadSafeActionClient
from robot_port.execution import Execution
from robot_port.hardware import HardwareUnavailable
from robot_port.tiago_interfaces import (
    BATTERY_STATE,
    CAMERA_DEPTH,
    CAMERA_IMAGE,
    CAMERA_INFO,
    CMD_VEL,
    COMPUTE_PATH_TO_POSE,
    DOCK_ROBOT,
    JOINT_STATES,
    LASER,
    NAVIGATE_TO_POSE,
    ODOMETRY,
    PLAY_MOTION2,
    TF,
    TF_STATIC,
    UNDOCK_ROBOT,
    controller_action,
)
from robot_port.types import JOINT_GROUPS, CameraFrame, JointTrajectory, LaserScan, Pose2D
from tiago_description import robot_model as rm
from tiago_description import transforms as tf
from tiago_description.robot_limits import active_limits
from tiago_ros_hardware.base_loops import drive_loop, velocity_loop
from tiago_ros_hardware.camera_messages import decoded, frame_pair
from tiago_ros_hardware.executions import FailedExecution, GoalsExecution, LoopExecution
from tiago_ros_hardware.frames import RobotFrames, yaw_of
from tiago_ros_hardware.nav2_goals import map_pose, path_poses, path_request, result_of
from tiago_ros_hardware.topics import TopicHistory, stamp_seconds
from tiago_ros_hardware.trajectory_goals import controller_goals, duration_msg

READING_TIMEOUT_S = 30.0
"""Wall seconds a reading may wait for its topic before the robot counts as gone."""
NAVIGATION_SPEED_MPS = 0.5  # for the time-left estimate of a navigation goal only
DOCKING_S = 8.0  # for the time-left estimate of docking and undocking only
PLANNING_TIMEOUT_S = 10.0  # wall seconds for Nav2's planner to answer


class RosHardware:
    """robot_port.RobotHardware on the robot's ROS 2 interfaces, through `node`."""

    def __init__(self, node: Node, dock_id: str = "", simulated_clock: bool = True) -> None:
        """`simulated_clock`: the robot's time is a simulator's `/clock`, not the node's wall clock."""
        self.node = node
        self.dock_id = dock_id
        self.simulated_clock = simulated_clock
        self._group = ReentrantCallbackGroup()
        self._lock = threading.Lock()
        self._busy: dict[str, Execution] = {}
        self._clock_s: float | None = None
        self._clock_changed = threading.Condition()
        self.frames = RobotFrames(READING_TIMEOUT_S)  # localisation's correction, the fixed frames
        self.joints = TopicHistory(JOINT_STATES)
        self.odom = TopicHistory(ODOMETRY)
        self.scans = TopicHistory(LASER)
        self.images = TopicHistory(CAMERA_IMAGE)
        self.depths = TopicHistory(CAMERA_DEPTH)
        self.infos = TopicHistory(CAMERA_INFO)
        self.battery = TopicHistory(BATTERY_STATE)
        reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self._subscribe(Clock, "/clock", self._on_clock, reliable)
        self._subscribe(JointState, JOINT_STATES, self._on_joints, reliable)
        self._subscribe(Odometry, ODOMETRY, self._on_odometry, reliable)
        self._subscribe(TFMessage, TF, self.frames.on_tf, reliable)
        latched = QoSProfile(
            depth=10, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
        )
        self._subscribe(TFMessage, TF_STATIC, self.frames.on_tf_static, latched)
        self._subscribe(BatteryState, BATTERY_STATE, self.battery.add, reliable)
        self._settled = {"joints": 0, "odom": 0, "battery": 0}  # counts after which readings show it at rest
        self.cmd_vel = node.create_publisher(Twist, CMD_VEL, reliable)
        self.actions: dict[str, ActionClient] = {}  # every action the adapter sends goals to, by name
        self.controllers = {
            group: self._action(FollowJointTrajectory, controller_action(group)) for group in JOINT_GROUPS
        }
        self.navigation = self._action(NavigateToPose, NAVIGATE_TO_POSE)
        self.planner = self._action(ComputePathToPose, COMPUTE_PATH_TO_POSE)
        self.docking = self._action(DockRobot, DOCK_ROBOT)
        self.undocking = self._action(UndockRobot, UNDOCK_ROBOT)
        self.named_motions = self._action(PlayMotion2, PLAY_MOTION2)
        self.limits = dict(active_limits().joint_velocity)

    def wait_until_ready(self, timeout_s: float = READING_TIMEOUT_S) -> None:
        """Return once every action server the adapter sends goals to answers and the joints,
        odometry (and, on a simulator, the clock) have been heard; else HardwareUnavailable naming
        what is missing. Why: a goal sent before its server is discovered can be lost unanswered."""
        for name, client in self.actions.items():
            if not client.wait_for_server(timeout_sec=timeout_s):
                raise HardwareUnavailable(f"no action server {name} within {timeout_s:.0f} s")
        for history in (self.joints, self.odom):
            history.after(0, timeout_s)  # HardwareUnavailable names the topic
        if self.simulated_clock:
            self.now()

    def _action(self, kind: Any, name: str) -> ActionClient:
        self.actions[name] = ThreadSafeActionClient(self.node, kind, name, callback_group=self._group)
        return self.actions[name]

    def _subscribe(self, kind: Any, topic: str, callback: Any, qos: QoSProfile) -> None:
        self.node.create_subscription(kind, topic, callback, qos, callback_group=self._group)

    # -- topics -> histories --------------------------------------------------------------------
    def _on_clock(self, message: Clock) -> None:
        with self._clock_changed:
            self._clock_s = message.clock.sec + message.clock.nanosec * 1e-9
            self._clock_changed.notify_all()

    def _on_joints(self, message: JointState) -> None:
        self.joints.add(dict(zip(message.name, message.position, strict=True)), stamp_seconds(message))

    def _on_odometry(self, message: Odometry) -> None:
        pose = message.pose.pose
        planar = (float(pose.position.x), float(pose.position.y), yaw_of(pose.orientation))
        twist = message.twist.twist
        self.odom.add((planar, (float(twist.linear.x), float(twist.angular.z))), stamp_seconds(message))

    # -- clock and readings --------------------------------------------------------------------
    def now(self) -> float:
        if not self.simulated_clock:
            return self.node.get_clock().now().nanoseconds * 1e-9
        with self._clock_changed:
            if not self._clock_changed.wait_for(lambda: self._clock_s is not None, READING_TIMEOUT_S):
                raise HardwareUnavailable("no /clock from the robot")
            return float(self._clock_s)

    def _now_or_zero(self) -> float:
        if not self.simulated_clock:
            return self.now()
        return float(self._clock_s or 0.0)

    def joint_positions(self) -> dict[str, float]:
        return dict(self.joints.after(self._settled["joints"], READING_TIMEOUT_S)[1])

    def odometry(self) -> Pose2D:
        return self._fresh_odometry()[0]

    def _fresh_odometry(self) -> tuple[Pose2D, tuple[float, float]]:
        return self.odom.after(self._settled["odom"], READING_TIMEOUT_S)[1]

    def _command_ended(self) -> None:
        """Readings from now on wait for messages sent after the end: the next but one of each topic."""
        self._settled = {name: history.count + 1 for name, history in self._histories().items()}

    def _histories(self) -> dict[str, TopicHistory]:
        return {"joints": self.joints, "odom": self.odom, "battery": self.battery}

    def pose_estimate(self) -> Pose2D:
        return tf.compose_planar(self.frames.correction, self.odometry())

    def is_docked(self) -> bool:
        state = self.battery.after(self._settled["battery"], READING_TIMEOUT_S)[1]
        return state.power_supply_status == BatteryState.POWER_SUPPLY_STATUS_CHARGING

    def laser_scan(self) -> LaserScan:
        settled, _odometry = self.odom.after(self._settled["odom"], READING_TIMEOUT_S)
        with self._listening((LASER, LaserScanMsg, self.scans)):
            stamp, message = self.scans.newer_than(settled - 1e-9, READING_TIMEOUT_S)
        odometry = self.odom.at(stamp)
        ranges = np.array(message.ranges, dtype=float)
        ranges[~np.isfinite(ranges) | (ranges > message.range_max)] = np.inf
        return LaserScan(
            ranges=ranges,
            angle_min=float(message.angle_min),
            angle_increment=float(message.angle_increment),
            range_min=float(message.range_min),
            range_max=float(message.range_max),
            mount=self.frames.mount(message.header.frame_id),
            odometry=odometry[0] if odometry is not None else self.odometry(),
            stamp_s=stamp,
        )

    def capture_head_camera(self) -> CameraFrame:
        settled, _joints = self.joints.after(self._settled["joints"], READING_TIMEOUT_S)
        with self._listening(
            (CAMERA_IMAGE, Image, self.images),
            (CAMERA_DEPTH, Image, self.depths),
            (CAMERA_INFO, CameraInfo, self.infos),
        ):
            stamp, image, depth = frame_pair(self.images, self.depths, settled, READING_TIMEOUT_S)
            _, info = self.infos.newer_than(stamp - 1e-9, READING_TIMEOUT_S)  # the same intrinsics always
        rgb, metres, intrinsics = decoded(image, depth, info)
        joints = self.joints.at(stamp) or self.joint_positions()
        odometry = self.odom.at(stamp)
        return CameraFrame(
            rgb, metres, intrinsics, dict(joints), odometry[0] if odometry else self.odometry(), stamp
        )

    @contextmanager
    def _listening(self, *topics: tuple[str, Any, TopicHistory]) -> Iterator[None]:
        """Subscribed to `topics` for the block only: a simulator renders its camera and casts its
        laser only while someone listens, and a robot's images are heavy on the network. No QoS event
        handlers: rclpy 7.1 adds them to a wait set unguarded, and one destroyed meanwhile ended an
        executor thread (loaded CI: "destruction was requested", then no reading came)."""
        qos = QoSProfile(depth=2, reliability=ReliabilityPolicy.RELIABLE)
        no_events = SubscriptionEventCallbacks(use_default_callbacks=False)
        subscriptions = [
            self.node.create_subscription(
                kind, topic, history.add, qos, callback_group=self._group, event_callbacks=no_events
            )
            for topic, kind, history in topics
        ]
        try:
            yield
        finally:
            for subscription in subscriptions:
                self.node.destroy_subscription(subscription)

    # -- commands ------------------------------------------------------------------------------
    def _claim(self, groups: set[str], execution: Any) -> Execution:
        """`execution` (a callable starting it) unless one of `groups` is moving for another command."""
        with self._lock:
            taken = sorted(g for g in groups if g in self._busy and not self._busy[g].done)
            if taken:
                return FailedExecution("busy", "BUSY", f"busy: {taken}")
            started = execution()
            for group in groups:
                self._busy[group] = started
        return started

    def follow_joint_trajectory(self, trajectory: JointTrajectory) -> Execution:
        unknown = [name for name in trajectory.joint_names if name not in self.limits]
        if unknown or not trajectory.points:
            why = f"joints the robot does not have: {unknown}" if unknown else "no points"
            return FailedExecution(trajectory.name, "BAD_GOAL", why)
        start = self.joint_positions()
        goals, duration = controller_goals(trajectory, start, self.limits)
        sent = [(controller_action(group), self.controllers[group], goal) for group, goal in goals.items()]
        return self._claim(
            set(goals),
            lambda: GoalsExecution(
                trajectory.name,
                sent,
                self._now_or_zero,
                duration,
                "MOTION_FAILED",
                on_end=self._command_ended,
            ),
        )

    def gripper(self, side: str, close: bool) -> Execution:
        if side not in rm.ARM_SIDES:
            return FailedExecution("gripper", "BAD_GOAL", f"unknown arm {side!r}")
        group = f"gripper_{side}"
        fingers = rm.finger_joint_names(side)
        target = 0.0 if close else rm.FINGER_TRAVEL - 0.001
        seconds = rm.FINGER_TRAVEL / active_limits().finger_speed
        goal = FollowJointTrajectory.Goal()
        goal.trajectory.joint_names = fingers
        point = JointTrajectoryPoint(positions=[target] * len(fingers), time_from_start=duration_msg(seconds))
        goal.trajectory.points.append(point)

        def reading() -> dict[str, Any]:
            positions = [self.joint_positions()[name] for name in fingers]
            return {"holding": rm.holds_by_gap(close, positions), "opening_m": rm.finger_gap(positions)}

        sent = [(controller_action(group), self.controllers[group], goal)]
        name = f"gripper_{side}_{'close' if close else 'open'}"
        return self._claim(
            {group},
            lambda: GoalsExecution(
                name, sent, self._now_or_zero, seconds, "GRASP_FAILED", reading, self._command_ended
            ),
        )

    def command_velocity(self, linear_mps: float, angular_radps: float, duration_s: float) -> Execution:
        return self._claim(
            {"base"},
            lambda: LoopExecution(
                "velocity", self._now_or_zero, duration_s,
                lambda run: velocity_loop(self, run, linear_mps, angular_radps, duration_s),
                self._command_ended,
            ),
        )  # fmt: skip

    def drive_to(self, goal: Pose2D, speed_mps: float) -> Execution:
        here = self.odometry()
        seconds = math.dist(goal[:2], here[:2]) / max(speed_mps, 1e-3) + 1.0
        return self._claim(
            {"base"},
            lambda: LoopExecution(
                "drive",
                self._now_or_zero,
                seconds,
                lambda run: drive_loop(self, run, goal, speed_mps),
                self._command_ended,
            ),
        )

    def navigate_to(self, goal: Pose2D, goal_name: str) -> Execution:
        here = self.pose_estimate()
        seconds = math.dist(goal[:2], here[:2]) / NAVIGATION_SPEED_MPS + abs(
            math.remainder(goal[2] - here[2], math.tau)
        )
        request = NavigateToPose.Goal(pose=map_pose(goal))
        sent = (NAVIGATE_TO_POSE, self.navigation, request)
        return self._one_goal({"base"}, f"navigate to {goal_name}", sent, seconds, "NAVIGATION_FAILED")

    def plan_path(self, start: Pose2D, goal: Pose2D) -> tuple[Pose2D, ...]:
        result = result_of(self.planner, path_request(start, goal), PLANNING_TIMEOUT_S)
        return () if result is None else path_poses(result.path)

    def dock(self) -> Execution:
        goal = DockRobot.Goal(use_dock_id=True, dock_id=self.dock_id, navigate_to_staging_pose=False)
        return self._one_goal({"base"}, "dock", (DOCK_ROBOT, self.docking, goal), DOCKING_S)

    def undock(self) -> Execution:
        sent = (UNDOCK_ROBOT, self.undocking, UndockRobot.Goal())
        return self._one_goal({"base"}, "undock", sent, DOCKING_S)

    def play_motion(self, key: str, skip_planning: bool = False, expected_s: float = 5.0) -> Execution:
        """A named motion of the robot's play_motion2, the arms, torso and head claimed meanwhile;
        for a lab's tools, not the port's (the skills time their own keyframes). `skip_planning`
        False lets MoveIt plan the approach (PAL's advice); `expected_s`: the time-left estimate."""
        goal = PlayMotion2.Goal(motion_name=key, skip_planning=skip_planning)
        groups = {"arm_left", "arm_right", "torso", "head"}
        return self._one_goal(groups, f"motion {key}", (PLAY_MOTION2, self.named_motions, goal), expected_s)

    def _one_goal(
        self,
        groups: set[str],
        name: str,
        sent: tuple[str, ActionClient, Any],
        seconds: float,
        code: str = "MOTION_FAILED",
    ) -> Execution:
        """One goal (action, client, goal) with `groups` claimed; `code` names a failure."""
        return self._claim(
            groups,
            lambda: GoalsExecution(
                name, [sent], self._now_or_zero, seconds, code, on_end=self._command_ended
            ),
        )

    # -- for the loops -------------------------------------------------------------------------
    def publish_twist(self, linear: float, angular: float) -> None:
        twist = Twist()
        twist.linear.x, twist.angular.z = float(linear), float(angular)
        self.cmd_vel.publish(twist)

    def base_motion(self) -> tuple[Pose2D, tuple[float, float]]:
        """The base's odometry pose and its speeds (linear m/s, angular rad/s), fresh."""
        return self._fresh_odometry()

    def next_base_motion(self) -> tuple[Pose2D, tuple[float, float]]:
        """As `base_motion`, from the next odometry message to arrive (a loop's next step)."""
        return self.odom.after(self.odom.count, READING_TIMEOUT_S)[1]
