"""Our own TIAGo++ model, generated as URDF text from primitive shapes.

Why generated: one source of numbers (PAL's public kinematics, see the project notes) feeds both
PyBullet and pinocchio, and nothing of PAL's meshes is needed. The root link is
``base_footprint`` (on the floor, x forward, z up), as on the real robot.

Modelling choices (see also README.md, "The world file"):
- Base: kinematic differential drive. The simulation moves the base through a constraint that
  follows the commanded planar velocity (limited in speed and acceleration) and derives the wheel
  encoder readings from the base's motion. The wheels are fixed links without collision shapes
  (two moving links less make every physics step about 10 % cheaper); the URDF is the same for
  PyBullet and pinocchio.
- Gripper: two prismatic fingers, 0..0.045 m each, like PAL's. Our fingers sit 5 mm further out
  than PAL's, so the gap runs from 10 mm (closed) to 100 mm (open) instead of 0..90 mm: 7.3 mm
  clearance per side over a microplate's 85.48 mm short side. Pads are 80 mm wide.
- ``gripper_<side>_grasping_frame``: origin between the finger pads, x = approach direction (out of
  the palm), y = closing axis of the fingers (towards the left finger), z = x cross y.
- Onboard hotel: a tray on the base front with two pockets; fixed links ``hotel_slot_<n>`` lie on
  the pocket floor centre, x along the plate's long side, z up.
"""

from __future__ import annotations

import hashlib
import math
import os
import tempfile
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from tiago_description.hotel_model import add_hotel
from tiago_description.urdf_writer import UrdfWriter

ARM_SIDES = ("right", "left")
DEG = math.pi / 180.0

# Drive (PMB2 base)
WHEEL_RADIUS = 0.0985
WHEEL_SEPARATION = 0.4044
BASE_RADIUS = 0.265
# The base's hardware maxima; the limits a lab runs the robot with are robot_limits' (at most these).
MAX_LINEAR_SPEED = 1.0
MAX_ANGULAR_SPEED = 1.0
MAX_LINEAR_ACCEL = 0.5
MAX_ANGULAR_ACCEL = 1.0

TORSO_LIFT_RANGE = (0.0, 0.35)
TORSO_LIFT_SPEED = 0.07

# Gripper
LASER_MOUNT = (0.202, 0.0, 0.0)
"""The base laser's frame (base_laser_link) in base_footprint: x, y (m) and yaw (rad)."""
LASER_HEIGHT = WHEEL_RADIUS - 0.004
"""The base laser's frame above the floor (m)."""
FINGER_TRAVEL = 0.045
FINGER_MOUNT_OFFSET = 0.005  # inner pad face at this distance from centre when a finger joint is 0
# Fingers closed on nothing stop with their pads 2 * FINGER_MOUNT_OFFSET apart; closed further apart
# than this, they hold something. The one "holding" rule of a real gripper (its joint states), for
# the ROS adapter, the simulator's reports and the grasp's result alike.
HOLDING_GAP_M = 2 * FINGER_MOUNT_OFFSET + 0.002


def finger_gap(finger_positions: Iterable[float]) -> float:
    """The gap between the pads (m) for the two finger joints' positions."""
    return 2 * FINGER_MOUNT_OFFSET + sum(finger_positions)


def holds_by_gap(closed: bool, finger_positions: Iterable[float]) -> bool:
    """Whether a gripper commanded closed holds something, from its fingers' positions alone."""
    return closed and finger_gap(finger_positions) > HOLDING_GAP_M


FINGER_SPEED = 0.05
FINGER_EFFORT = 16.0
PAD_THICKNESS = 0.010
PAD_WIDTH = 0.080  # along grasping-frame z (along the plate's long side)
# An arm reaches a nest top-down (grasp and approach, torso free) from 0 to this far to its side of
# the base's centre line, from a working pose 0.45 to 0.55 m in front of the nests, for nests 0.55
# to 0.80 m high (measured with this model's IK: tiago_sim.layouts.station_draw).
TOP_DOWN_REACH_BAND_M = 0.45
PAD_TIP = 0.005  # pad reaches this far past the grasping frame along x
PAD_LENGTH = 0.035  # along grasping-frame x
TOOL_TO_GRASP = 0.1506 + 0.12


@dataclass(frozen=True)
class ArmJoint:
    """One arm joint of the right arm; the left arm is derived with reflect = -1."""

    name: str
    limits_deg: tuple[float, float]
    velocity: float
    effort: float


ARM_JOINTS = (
    ArmJoint("1", (-67.5, 90.0), 1.95, 43.0),
    ArmJoint("2", (-67.5, 90.0), 1.95, 43.0),
    ArmJoint("3", (-45.0, 225.0), 2.35, 26.0),
    ArmJoint("4", (-22.5, 135.0), 2.35, 26.0),
    ArmJoint("5", (-120.0, 120.0), 1.95, 3.0),
    ArmJoint("6", (-81.0, 81.0), 1.76, 6.6),
    ArmJoint("7", (-120.0, 120.0), 1.76, 6.6),
)
ARM_LINK_MASSES = (1.6, 1.6, 1.4, 1.0, 0.6, 0.3, 0.2)


def arm_joint_origins(reflect: int) -> list[tuple[tuple[float, float, float], tuple[float, float, float]]]:
    """Origins (xyz m, rpy rad) of arm joints 2..7 and the tool joint, mirrored by ``reflect``."""
    r = reflect
    d = DEG
    return [
        ((0.125, -0.0195, -0.031 * r), (-90 * r * d, 0.0, 0.0)),
        ((0.0895, 0.0, -0.0015), (-90 * d, (90 - 90 * r) * d, 90 * r * d)),
        ((-0.02, -0.027, -0.222 * r), (-90 * r * d, -90 * d, 0.0)),
        ((-0.162 * r, 0.02 * r, 0.027 * r), (90 * d, -90 * d, -90 * d)),
        ((0.0, 0.0, 0.15 * r), (0.0, -90 * d, -90 * d)),
        ((0.0, 0.0, 0.0), (90 * d, 0.0, 90 * d)),
        ((0.0, 0.0, 0.046 * r), (90 * d, -90 * r * d, 180 * d)),
    ]


def arm_joint_names(side: str) -> list[str]:
    """URDF names of the seven joints of one arm, shoulder first."""
    return [f"arm_{side}_{joint.name}_joint" for joint in ARM_JOINTS]


def controller_joints(group: str) -> list[str]:
    """The joints a controller of the robot moves (robot_port.types.JOINT_GROUPS), in the order of
    PAL's controller files."""
    if group.startswith("arm_"):
        return arm_joint_names(group.removeprefix("arm_"))
    if group.startswith("gripper_"):
        return finger_joint_names(group.removeprefix("gripper_"))
    if group == "torso":
        return ["torso_lift_joint"]
    if group == "head":
        return [f"{joint.name}_joint" for joint in HEAD_JOINTS]
    raise ValueError(f"no controller for {group!r}")


def finger_joint_names(side: str) -> list[str]:
    """URDF names of the two finger joints of one gripper (left finger, right finger)."""
    return [f"gripper_{side}_left_finger_joint", f"gripper_{side}_right_finger_joint"]


def _add_base(w: UrdfWriter) -> None:
    w.link("base_footprint", 1.0)  # its inertial origin makes PyBullet's base frame = base_footprint
    w.link(
        "base_link",
        28.0,
        [("cylinder", (BASE_RADIUS, 0.275), (0, 0, 0.0615), (0, 0, 0), "white")],
    )
    w.joint("base_footprint_joint", "fixed", "base_footprint", "base_link", (0, 0, WHEEL_RADIUS))
    for side, sign in (("right", -1.0), ("left", 1.0)):
        w.link(
            f"wheel_{side}_link",
            1.0,
            [("cylinder", (WHEEL_RADIUS, 0.04), (0, 0, 0), (math.pi / 2, 0, 0), "dark")],
            collide=False,
        )
        w.joint(  # fixed: the drive is kinematic, see the module docstring
            f"wheel_{side}_joint",
            "fixed",
            "base_link",
            f"wheel_{side}_link",
            (0, sign * WHEEL_SEPARATION / 2, 0),
            axis=(0, 1, 0),
            effort=6.0,
            velocity=10.0,
        )
    for i, (cx, cy) in enumerate(((0.1715, 0.102), (0.1715, -0.102), (-0.1715, 0.102), (-0.1715, -0.102))):
        w.link(
            f"caster_{i + 1}_link", 0.1, [("sphere", (0.025,), (0, 0, 0), (0, 0, 0), "dark")], collide=False
        )
        w.joint(f"caster_{i + 1}_joint", "fixed", "base_link", f"caster_{i + 1}_link", (cx, cy, -0.0735))


@dataclass(frozen=True)
class HeadJoint:
    """Pan (head_1) and tilt (head_2), with the link each one moves (no collision shape)."""

    name: str
    parent: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    limits_deg: tuple[float, float]
    effort: float  # N m
    mass: float  # kg of the link
    shape: tuple  # (shape, size, xyz, rpy, material) as UrdfWriter.link takes it


HEAD_SPEED = 3.0  # rad/s, both joints
HEAD_JOINTS = (
    HeadJoint(
        "head_1", "torso_lift_link", (0.182, 0, 0), (0, 0, 0), (-75.0, 75.0), 5.2, 0.5,
        ("cylinder", (0.04, 0.09), (0, 0, 0.045), (0, 0, 0), "dark"),
    ),
    HeadJoint(
        "head_2", "head_1_link", (0.005, 0, 0.098), (math.pi / 2, 0, 0), (-60.0, 45.0), 2.8, 0.8,
        ("box", (0.14, 0.12, 0.2), (0.03, 0.06, 0), (0, 0, 0), "white"),
    ),
)  # fmt: skip


def _add_torso_and_head(w: UrdfWriter) -> None:
    w.link("torso_fixed_link", 8.0, [("box", (0.24, 0.3, 0.5), (0, 0, 0.23), (0, 0, 0), "grey")])
    w.joint("torso_fixed_joint", "fixed", "base_link", "torso_fixed_link", (-0.062, 0, 0.193))
    w.link(
        "torso_lift_link",
        9.0,
        [
            ("box", (0.22, 0.26, 0.26), (0, 0, -0.16), (0, 0, 0), "white"),
            ("box", (0.12, 0.44, 0.06), (0.0, 0, -0.17), (0, 0, 0), "white"),
        ],
    )
    w.joint(
        "torso_lift_joint",
        "prismatic",
        "torso_fixed_link",
        "torso_lift_link",
        (0, 0, 0.597),
        axis=(0, 0, 1),
        limits=TORSO_LIFT_RANGE,
        effort=2000.0,
        velocity=TORSO_LIFT_SPEED,
    )
    for joint in HEAD_JOINTS:
        link = f"{joint.name}_link"
        w.link(link, joint.mass, [joint.shape], collide=False)
        w.joint(
            f"{joint.name}_joint",
            "revolute",
            joint.parent,
            link,
            joint.xyz,
            joint.rpy,
            limits=(joint.limits_deg[0] * DEG, joint.limits_deg[1] * DEG),
            effort=joint.effort,
            velocity=HEAD_SPEED,
        )
    # camera_link (x forward, z up when the head is at zero) and its OpenCV optical frame
    w.link(
        "head_camera_link", 0.05, [("box", (0.02, 0.1, 0.03), (0, 0, 0), (0, 0, 0), "dark")], collide=False
    )
    w.joint(
        "head_camera_joint",
        "fixed",
        "head_2_link",
        "head_camera_link",
        (0.091, 0.0805, -0.022),
        (-math.pi / 2, 0, 0),
    )
    w.link("head_front_camera_rgb_optical_frame")
    w.joint(
        "head_camera_optical_joint",
        "fixed",
        "head_camera_link",
        "head_front_camera_rgb_optical_frame",
        (0, 0, 0),
        (-math.pi / 2, 0, -math.pi / 2),
    )


def _add_arm(w: UrdfWriter, side: str) -> None:
    reflect = 1 if side == "right" else -1
    origins = arm_joint_origins(reflect)
    mount = (
        ((0.02556, -0.19, -0.171), (0, 0, -90 * DEG))
        if side == "right"
        else ((0.02556, 0.19, -0.171), (180 * DEG, 0, 90 * DEG))
    )
    parent = "torso_lift_link"
    joint_origins = [mount, *origins[:-1]]
    for index, (joint, (xyz, rpy)) in enumerate(zip(ARM_JOINTS, joint_origins, strict=True)):
        link = f"arm_{side}_{joint.name}_link"
        next_xyz = origins[index][0]
        radius = 0.05 if index < 4 else 0.04
        w.link(link, ARM_LINK_MASSES[index], w.segment_shapes(next_xyz, radius))
        w.joint(
            f"arm_{side}_{joint.name}_joint",
            "revolute",
            parent,
            link,
            xyz,
            rpy,
            limits=(joint.limits_deg[0] * DEG, joint.limits_deg[1] * DEG),
            effort=joint.effort,
            velocity=joint.velocity,
        )
        parent = link
    tool = f"arm_{side}_tool_link"
    w.link(tool)
    w.joint(f"arm_{side}_tool_joint", "fixed", parent, tool, *origins[-1])
    _add_gripper(w, side, tool)


def _add_gripper(w: UrdfWriter, side: str, tool: str) -> None:
    """Palm along the tool x axis, fingers sliding along the tool y axis."""
    palm = f"gripper_{side}_link"
    palm_length = TOOL_TO_GRASP - 0.12
    w.link(
        palm,
        0.35,
        [
            (
                "cylinder",
                (0.04, palm_length - 0.03),
                ((palm_length - 0.03) / 2, 0, 0),
                (0, math.pi / 2, 0),
                "dark",
            ),
            ("box", (0.03, 0.13, 0.06), (palm_length - 0.015, 0, 0), (0, 0, 0), "dark"),
        ],
    )
    w.joint(f"gripper_{side}_joint", "fixed", tool, palm)
    finger_length = 0.12 + PAD_TIP  # from the palm face to the pad tip
    for finger, sign in (("left", 1.0), ("right", -1.0)):
        link = f"gripper_{side}_{finger}_finger_link"
        inner_y = sign * (FINGER_MOUNT_OFFSET + PAD_THICKNESS / 2)
        shapes = [
            # shaft from palm to pad, then the wide pad at the tip
            (
                "box",
                (finger_length - PAD_LENGTH, 0.008, 0.02),
                ((finger_length - PAD_LENGTH) / 2, inner_y + sign * 0.004, 0),
                (0, 0, 0),
                "grey",
            ),
            (
                "box",
                (PAD_LENGTH, PAD_THICKNESS, PAD_WIDTH),
                (finger_length - PAD_LENGTH / 2, inner_y, 0),
                (0, 0, 0),
                "pad",
            ),
        ]
        w.link(link, 0.08, shapes)
        w.joint(
            f"gripper_{side}_{finger}_finger_joint",
            "prismatic",
            palm,
            link,
            (palm_length, 0, 0),
            axis=(0, sign, 0),
            limits=(0.0, FINGER_TRAVEL),
            effort=FINGER_EFFORT,
            velocity=FINGER_SPEED,
        )
    w.link(f"gripper_{side}_grasping_frame")
    w.joint(
        f"gripper_{side}_grasping_frame_joint",
        "fixed",
        tool,
        f"gripper_{side}_grasping_frame",
        (TOOL_TO_GRASP, 0, 0),
    )


def build_urdf() -> str:
    """URDF text of the whole robot."""
    writer = UrdfWriter("tiago_dual_sim")
    _add_base(writer)
    _add_torso_and_head(writer)
    for side in ARM_SIDES:
        _add_arm(writer, side)
    add_hotel(writer, WHEEL_RADIUS)
    _add_laser_frame(writer)  # last: the links before it keep their PyBullet indices
    return writer.text()


def _add_laser_frame(w: UrdfWriter) -> None:
    """The base laser's frame (no body: the laser is cast, see tiago_sim.physics.base_laser), so that
    the robot's fixed frames on /tf_static name it as a TIAGo++'s robot_state_publisher does."""
    x, y, yaw = LASER_MOUNT
    w.link("base_laser_link")
    w.joint(
        "base_laser_joint",
        "fixed",
        "base_link",
        "base_laser_link",
        (x, y, LASER_HEIGHT - WHEEL_RADIUS),
        (0, 0, yaw),
    )


def urdf_path() -> Path:
    """Path of the URDF file, written once per content into the temp dir (shared by sim and pinocchio)."""
    text = build_urdf()
    digest = hashlib.sha1(text.encode()).hexdigest()[:12]
    path = Path(tempfile.gettempdir()) / f"tiago_sim_{digest}.urdf"
    if not path.exists():
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(text)
        tmp.replace(path)
    return path
