"""The simulator spoken to as a TIAGo++ is, through the robot's own ROS 2 interfaces (tiago_twin
--robot-interfaces; the names and types in robot_port.tiago_interfaces).

A real rclpy client talks over DDS to the twin in its own process; joints and base move in
PyBullet and are read back from /joint_states and the ground truth. The controllers behave as
ros2_controllers' JointTrajectoryController does: invalid goals are rejected, a new goal preempts
the running one, a cancel stops the joints where they are. The base takes velocity commands as
diff_drive_controller does and navigation goals as Nav2 does.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest
from action_msgs.msg import GoalStatus
from builtin_interfaces.msg import Duration
from control_msgs.action import FollowJointTrajectory
from geometry_msgs.msg import Pose2D, PoseStamped, Twist
from labware_interfaces.action import Undock
from nav2_msgs.action import NavigateToPose
from nav_msgs.msg import Odometry
from play_motion2_msgs.action import PlayMotion2
from play_motion2_msgs.srv import IsMotionReady, ListMotions
from rclpy.action import get_action_names_and_types
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectoryPoint

from lab_description.world import DEFAULT_WORLD, load_world
from robot_port.tiago_interfaces import (
    CMD_VEL,
    IS_MOTION_READY,
    LIST_MOTIONS,
    NAVIGATE_TO_POSE,
    ODOMETRY,
    PLAY_MOTION2,
    TIAGO_INTERFACES,
    controller_action,
)
from robot_port.types import JOINT_GROUPS
from tests.helpers.ros_processes import RosCaller, running
from tiago_description.motion_library import load_motions
from tiago_description.robot_model import controller_joints
from tiago_sim.sim_node.named_motions import named_motions

HEAD = controller_action("head")
TORSO = controller_action("torso")


@pytest.fixture(scope="module")
def robot(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RosCaller]:
    log_path = tmp_path_factory.mktemp("ros_logs") / "twin.log"
    # at most 5 times real time: a 30 s goal lasts seconds of wall time, for a preempt or a cancel
    arguments = ["--world", str(DEFAULT_WORLD), "--seed", "3", "--robot-interfaces"]
    with running("tiago_twin", *arguments, "--realtime-factor-cap", "5", log_path=log_path):
        caller = RosCaller("test_robot_controllers")
        caller.subscribe(JointState, "/joint_states")
        caller.subscribe(Odometry, ODOMETRY)
        caller.subscribe(Pose2D, "/ground_truth/base_pose")
        try:
            caller.wait_for(lambda: "/joint_states" in caller.latest, 120.0, "the twin's /joint_states")
            yield caller
        finally:
            caller.close()


def joints_now(caller: RosCaller) -> dict[str, float]:
    """A /joint_states message that arrived after this call (so it shows what stands now)."""
    caller.latest.pop("/joint_states", None)
    caller.wait_for(lambda: "/joint_states" in caller.latest, 30.0, "a fresh /joint_states")
    message = caller.latest["/joint_states"]
    return dict(zip(message.name, message.position, strict=True))


def goal(
    names: list[str], *points: tuple[float, list[float], list[float] | None]
) -> FollowJointTrajectory.Goal:
    request = FollowJointTrajectory.Goal()
    request.trajectory.joint_names = names
    for at, positions, velocities in points:
        point = JointTrajectoryPoint(positions=positions, velocities=velocities or [])
        point.time_from_start = Duration(sec=int(at), nanosec=int(round((at % 1) * 1e9)))
        request.trajectory.points.append(point)
    return request


def test_every_controller_is_served_under_pals_name(robot: RosCaller) -> None:
    wanted = {
        controller_action(group): ["control_msgs/action/FollowJointTrajectory"] for group in JOINT_GROUPS
    }

    def served() -> bool:
        names = dict(get_action_names_and_types(robot.node))
        return all(names.get(name) == kind for name, kind in wanted.items())

    robot.wait_for(served, 30.0, "every controller's action")


def test_a_head_goal_moves_the_head_and_reports_its_progress(robot: RosCaller) -> None:
    names = controller_joints("head")
    start = joints_now(robot)
    target = [start[names[0]] + 0.3, start[names[1]] - 0.2]
    outcome = robot.call_action(FollowJointTrajectory, HEAD, goal(names, (1.5, target, None)), 60.0)
    assert outcome.status == GoalStatus.STATUS_SUCCEEDED
    assert outcome.result.error_code == FollowJointTrajectory.Result.SUCCESSFUL
    now = joints_now(robot)
    assert [now[name] for name in names] == pytest.approx(target, abs=0.02)
    assert outcome.feedback, "no feedback while the head moved"
    assert list(outcome.feedback[-1].joint_names) == names


def test_points_with_velocities_pass_through_each_point(robot: RosCaller) -> None:
    start = joints_now(robot)["torso_lift_joint"]
    up = min(start + 0.06, 0.34)
    points = ((1.0, [(start + up) / 2], [0.05]), (2.0, [up], [0.0]))
    outcome = robot.call_action(FollowJointTrajectory, TORSO, goal(["torso_lift_joint"], *points), 60.0)
    assert outcome.result.error_code == FollowJointTrajectory.Result.SUCCESSFUL
    assert joints_now(robot)["torso_lift_joint"] == pytest.approx(up, abs=0.01)


@pytest.mark.parametrize(
    "names, points, why",
    [
        (["head_1_joint", "torso_lift_joint"], ((1.0, [0.0, 0.1], None),), "a joint of another controller"),
        (["head_1_joint"], ((1.0, [0.0], None),), "a joint of the controller missing"),
        (["head_1_joint", "head_2_joint"], ((1.0, [0.0], None),), "a point short of a position"),
        (
            ["head_1_joint", "head_2_joint"],
            ((1.0, [0.0, 0.0], None), (0.5, [0.1, 0.0], None)),
            "time going back",
        ),
    ],
)
def test_an_invalid_goal_is_rejected(robot: RosCaller, names: list[str], points: tuple, why: str) -> None:
    handle = robot.send(FollowJointTrajectory, HEAD, goal(names, *points))
    assert not handle.accepted, why


def test_a_new_goal_preempts_the_running_one(robot: RosCaller) -> None:
    names = controller_joints("head")
    start = joints_now(robot)
    away = [start[names[0]] - 0.5, start[names[1]]]
    slow = robot.send(FollowJointTrajectory, HEAD, goal(names, (30.0, away, None)))
    assert slow.accepted
    robot.wait_for(lambda: slow.outcome.feedback, 30.0, "the first goal's start")
    target = [start[names[0]], start[names[1]] + 0.1]
    fast = robot.send(FollowJointTrajectory, HEAD, goal(names, (1.0, target, None)))
    assert fast.accepted
    first, second = robot.result(slow, 60.0), robot.result(fast, 60.0)
    assert first.status == GoalStatus.STATUS_ABORTED and "preempted" in first.result.error_string
    assert second.status == GoalStatus.STATUS_SUCCEEDED
    now = joints_now(robot)
    assert [now[name] for name in names] == pytest.approx(target, abs=0.02)


def test_a_cancelled_goal_stops_the_joints_where_they_are(robot: RosCaller) -> None:
    names = controller_joints("head")
    start = joints_now(robot)
    away = [start[names[0]] + 0.6, start[names[1]]]
    handle = robot.send(FollowJointTrajectory, HEAD, goal(names, (30.0, away, None)))
    robot.wait_for(lambda: handle.outcome.feedback, 30.0, "the goal's start")
    robot.spin_for(1.0)
    robot.spin_until(handle.cancel_goal_async(), 30.0)
    outcome = robot.result(handle, 60.0)
    assert outcome.status == GoalStatus.STATUS_CANCELED
    stopped = joints_now(robot)
    robot.spin_for(1.0)
    later = joints_now(robot)
    moved_on = later[names[0]] - stopped[names[0]]
    assert moved_on == pytest.approx(0.0, abs=0.005), "the head moved on after the cancel"
    assert start[names[0]] < stopped[names[0]] < start[names[0]] + 0.6, (
        "the head did not move, or went all the way"
    )


def test_a_gripper_goal_closes_and_opens_the_fingers(robot: RosCaller) -> None:
    names = controller_joints("gripper_left")
    action = controller_action("gripper_left")
    closed = robot.call_action(FollowJointTrajectory, action, goal(names, (1.0, [0.0, 0.0], None)), 60.0)
    assert closed.result.error_code == FollowJointTrajectory.Result.SUCCESSFUL
    assert max(joints_now(robot)[name] for name in names) < 0.003
    opened = robot.call_action(FollowJointTrajectory, action, goal(names, (1.0, [0.044, 0.044], None)), 60.0)
    assert opened.result.error_code == FollowJointTrajectory.Result.SUCCESSFUL
    assert min(joints_now(robot)[name] for name in names) > 0.04


def undocked(robot: RosCaller) -> None:
    outcome = robot.call_action(Undock, "/undock", Undock.Goal(), 120.0)
    assert outcome.result.success or "not docked" in outcome.result.message, outcome.result.message


def test_a_velocity_command_drives_the_base_until_it_stops_coming(robot: RosCaller) -> None:
    undocked(robot)
    publisher = robot.node.create_publisher(Twist, CMD_VEL, 10)
    robot.wait_for(lambda: publisher.get_subscription_count() > 0, 30.0, "the velocity input")
    robot.latest.pop(ODOMETRY, None)
    robot.wait_for(lambda: ODOMETRY in robot.latest, 30.0, "odometry")
    before = robot.latest[ODOMETRY].pose.pose.position
    command = Twist()
    command.linear.x = 0.1
    for _ in range(20):  # 1 s of wall time, 5 s of robot time at the twin's pace cap
        publisher.publish(command)
        robot.spin_for(0.05)
    robot.spin_for(1.0)  # the command runs out (0.5 s of robot time) and the base brakes
    robot.latest.pop(ODOMETRY, None)
    robot.wait_for(lambda: ODOMETRY in robot.latest, 30.0, "odometry")
    stopped = robot.latest[ODOMETRY].pose.pose.position
    robot.spin_for(1.0)
    robot.latest.pop(ODOMETRY, None)
    robot.wait_for(lambda: ODOMETRY in robot.latest, 30.0, "odometry")
    later = robot.latest[ODOMETRY].pose.pose.position
    robot.node.destroy_publisher(publisher)
    assert math.hypot(stopped.x - before.x, stopped.y - before.y) > 0.1, "the base did not drive"
    assert math.hypot(later.x - stopped.x, later.y - stopped.y) < 0.002, "the base drove on without commands"


def test_a_navigation_goal_brings_the_base_to_the_pose(robot: RosCaller) -> None:
    undocked(robot)
    world = load_world(DEFAULT_WORLD)
    station = world.stations[0]
    target = station.work_pose()
    request = NavigateToPose.Goal(pose=PoseStamped())
    request.pose.header.frame_id = "map"
    request.pose.pose.position.x, request.pose.pose.position.y = target.x, target.y
    request.pose.pose.orientation.z, request.pose.pose.orientation.w = (
        math.sin(target.yaw / 2),
        math.cos(target.yaw / 2),
    )
    outcome = robot.call_action(NavigateToPose, NAVIGATE_TO_POSE, request, 180.0)
    assert outcome.status == GoalStatus.STATUS_SUCCEEDED
    robot.latest.pop("/ground_truth/base_pose", None)
    robot.wait_for(lambda: "/ground_truth/base_pose" in robot.latest, 30.0, "the true pose")
    truth = robot.latest["/ground_truth/base_pose"]
    assert math.hypot(truth.x - target.x, truth.y - target.y) < 0.25  # Nav2's default goal checker
    assert abs(math.remainder(truth.theta - target.yaw, math.tau)) < 0.25


def test_every_interface_of_the_list_is_served_under_its_name_and_type(robot: RosCaller) -> None:
    """robot_port.tiago_interfaces lists what software of a real TIAGo++ (and the ROS adapter) finds
    on the robot: the simulator serves every entry, with the listed type."""
    kinds = {
        "topic": robot.node.get_topic_names_and_types,
        "action": lambda: get_action_names_and_types(robot.node),
        "service": robot.node.get_service_names_and_types,
    }
    missing: list[str] = []

    def served() -> bool:
        found = {kind: dict(names()) for kind, names in kinds.items()}
        missing[:] = [
            f"{interface.kind} {interface.name} ({interface.type})"
            for interface in TIAGO_INTERFACES
            if interface.type not in found[interface.kind].get(interface.name, [])
        ]
        return not missing

    try:
        robot.wait_for(served, 30.0, "every listed interface")
    except AssertionError as error:
        raise AssertionError(f"not served: {missing}") from error


def test_named_motions_are_listed_and_played_through_the_controllers(robot: RosCaller) -> None:
    keys = robot.call_service(ListMotions, LIST_MOTIONS, ListMotions.Request()).motion_keys
    assert {"travel_right", "tuck_left", "benchtop_right"} <= set(keys)
    ready = robot.call_service(IsMotionReady, IS_MOTION_READY, IsMotionReady.Request(motion_key="tuck_right"))
    assert ready.is_ready
    unknown = robot.call_service(IsMotionReady, IS_MOTION_READY, IsMotionReady.Request(motion_key="wave"))
    assert not unknown.is_ready

    outcome = robot.call_action(PlayMotion2, PLAY_MOTION2, PlayMotion2.Goal(motion_name="tuck_right"), 120.0)
    assert outcome.status == GoalStatus.STATUS_SUCCEEDED and outcome.result.success, outcome.result.error
    last = named_motions(load_motions())["tuck_right"].frames[-1]
    now = joints_now(robot)
    assert [now[name] for name in last] == pytest.approx(list(last.values()), abs=0.02)

    refused = robot.call_action(PlayMotion2, PLAY_MOTION2, PlayMotion2.Goal(motion_name="wave"), 60.0)
    assert refused.status == GoalStatus.STATUS_ABORTED and not refused.result.success
    assert "unknown motion 'wave'" in refused.result.error and "tuck_right" in refused.result.error
