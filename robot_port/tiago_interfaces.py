"""The ROS 2 interfaces a TIAGo++ offers its software: names and types, as PAL's and Nav2's sources
state them (docs/reference/robot-interfaces.md cites each).

Why one list: software that runs a real robot finds it under these names, so the simulator serves
the same ones (tiago_twin --robot-interfaces) and an adapter of the hardware port speaks them. A
test checks that the simulator serves every entry. Plain data: no ROS import here.
"""

from __future__ import annotations

from dataclasses import dataclass

from robot_port.types import JOINT_GROUPS


@dataclass(frozen=True)
class RosInterface:
    """One topic or action: its name, its type, and what it carries for the robot's software."""

    name: str
    type: str
    kind: str  # "topic", "action" or "service"
    what: str


def controller_action(group: str) -> str:
    """The FollowJointTrajectory action of a joint group's controller."""
    return f"/{group}_controller/follow_joint_trajectory"


CMD_VEL = "/mobile_base_controller/cmd_vel_unstamped"
ODOMETRY = "/mobile_base_controller/odom"
LASER = "/scan_raw"
CAMERA_IMAGE = "/head_front_camera/rgb/image_raw"
CAMERA_INFO = "/head_front_camera/rgb/camera_info"
CAMERA_DEPTH = "/head_front_camera/depth_registered/image_raw"
JOINT_STATES = "/joint_states"
NAVIGATE_TO_POSE = "/navigate_to_pose"
COMPUTE_PATH_TO_POSE = "/compute_path_to_pose"
DOCK_ROBOT = "/dock_robot"
UNDOCK_ROBOT = "/undock_robot"
BATTERY_STATE = "/battery_state"
TF = "/tf"
TF_STATIC = "/tf_static"
PLAY_MOTION2 = "/play_motion2"
LIST_MOTIONS = "/play_motion2/list_motions"
IS_MOTION_READY = "/play_motion2/is_motion_ready"

TIAGO_INTERFACES: tuple[RosInterface, ...] = (
    *(
        RosInterface(
            controller_action(group),
            "control_msgs/action/FollowJointTrajectory",
            "action",
            f"the {group.replace('_', ' ')} controller's trajectories",
        )
        for group in JOINT_GROUPS
    ),
    RosInterface(
        CMD_VEL, "geometry_msgs/msg/Twist", "topic", "the base's velocity command (through twist_mux)"
    ),
    RosInterface(ODOMETRY, "nav_msgs/msg/Odometry", "topic", "wheel odometry"),
    RosInterface(LASER, "sensor_msgs/msg/LaserScan", "topic", "the base laser"),
    RosInterface(CAMERA_IMAGE, "sensor_msgs/msg/Image", "topic", "the head camera's colour image"),
    RosInterface(CAMERA_INFO, "sensor_msgs/msg/CameraInfo", "topic", "the head camera's intrinsics"),
    RosInterface(CAMERA_DEPTH, "sensor_msgs/msg/Image", "topic", "depth registered to the colour image"),
    RosInterface(JOINT_STATES, "sensor_msgs/msg/JointState", "topic", "every joint's reading"),
    RosInterface(TF, "tf2_msgs/msg/TFMessage", "topic", "localisation's map -> odom correction"),
    RosInterface(
        TF_STATIC, "tf2_msgs/msg/TFMessage", "topic", "the robot's fixed frames (the laser's mount)"
    ),
    RosInterface("/clock", "rosgraph_msgs/msg/Clock", "topic", "the simulator's time (a simulation only)"),
    RosInterface(NAVIGATE_TO_POSE, "nav2_msgs/action/NavigateToPose", "action", "Nav2's navigation goal"),
    RosInterface(
        COMPUTE_PATH_TO_POSE,
        "nav2_msgs/action/ComputePathToPose",
        "action",
        "Nav2's planner: a path to a pose, not driven",
    ),
    RosInterface(
        PLAY_MOTION2, "play_motion2_msgs/action/PlayMotion2", "action", "named motions (play_motion2)"
    ),
    RosInterface(LIST_MOTIONS, "play_motion2_msgs/srv/ListMotions", "service", "the named motions' keys"),
    RosInterface(
        IS_MOTION_READY, "play_motion2_msgs/srv/IsMotionReady", "service", "whether a named motion can play"
    ),
    # lab-added: Nav2's docking server and the battery state its charging dock reads
    RosInterface(DOCK_ROBOT, "nav2_msgs/action/DockRobot", "action", "onto the charging dock"),
    RosInterface(UNDOCK_ROBOT, "nav2_msgs/action/UndockRobot", "action", "off the charging dock"),
    RosInterface(BATTERY_STATE, "sensor_msgs/msg/BatteryState", "topic", "charging while on the dock"),
)
"""What the simulator serves (with --robot-interfaces). The skills use all but /play_motion2 and its
services: they time their own keyframes and chain them with straight tool moves (see
docs/reference/robot-interfaces.md); the adapter plays named motions for a lab's tools."""
