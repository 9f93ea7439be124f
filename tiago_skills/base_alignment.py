"""Marker-guided final approach: from the station's POI to the working pose in front of the nests.

Why: navigation ends a few centimetres and degrees off its goal (localisation error), and the
onboard hotel tray reaches 0.33 m ahead of the base centre. Standing at the working distance
straight from navigation, a 3 to 9 cm error made the turning base sweep the tray into the table
and knock the plate out of its pocket, or left the arm no room to unfold. So navigation stops farther
back (the station's ``standoff``, 0.22 m behind the working pose: navigation error and odometry drift
together have reached 18 cm); then the robot looks at the station's marker, works out where the working
pose (``work_standoff``) really is, and drives the last ~22 cm there. The torso rises to the bench
working height and the head turns to the bench during that drive (independent joints overlap).

Only robot knowledge is used: the head camera image and depth, joint readings, odometry, the
localised pose and the kinematic model; the station's geometry comes from the believed (nominal) world file.
Lives on: an rclpy executor thread (inside a /marker_motion goal).
"""

from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np
from labware_interfaces.msg import ErrorCodes

from lab_description.station_placement import nest_working_pose
from lab_description.world import Station
from robot_port.execution import Execution
from tiago_description import transforms as tf
from tiago_description.kinematics import RobotKinematics, head_aim, head_angles_towards, within_head_limits
from tiago_skills.goal_run import ActionAbort, GoalRun
from tiago_skills.joint_commands import move_joints

log = logging.getLogger(__name__)

HEAD_JOINTS = ("head_1_joint", "head_2_joint")
# rad; the camera sees 63 deg across. The second look repeats the first once the torso stands.
SEARCH_PAN_OFFSETS = (0.0, 0.0, 0.45, -0.45, 0.9, -0.9)
ALIGN_SPEED = 0.3  # m/s cap for the short final drive (the acceleration limit keeps it lower anyway)


def planar(transform: np.ndarray) -> tuple[float, float, float]:
    """x, y and heading of a frame's x axis projected on the floor plane."""
    return float(transform[0, 3]), float(transform[1, 3]), math.atan2(transform[1, 0], transform[0, 0])


def search_marker(
    run: GoalRun, kinematics: RobotKinematics, target: np.ndarray, look: Any, lifting: Any
) -> Any:
    """Point the head where the marker should be and look; if it is not in the image, pan left and
    right and look again (odometry drifts over a long drive: a robot has arrived 18 cm and 5 deg
    off its belief). Every extra look is logged; MARKER_NOT_FOUND only when all of them fail.

    The first look happens while the torso still rises to the bench height; a torso left low by
    an earlier motion rises for seconds and carried the marker out of the image's bottom edge. So
    a further look first lets the torso arrive and aims from the joints read then."""
    failure: ActionAbort | None = None
    for index, pan_offset in enumerate(SEARCH_PAN_OFFSETS):
        if index:
            side = "left" if pan_offset > 0 else "right"
            further = f"{abs(math.degrees(pan_offset)):.0f} deg further {side}"
            log.info("marker not in view: looking %s", further if pan_offset else "again, the torso at rest")
            if lifting is not None:
                run.follow(lifting, span=(0.0, 0.15))
        joints = run.read(lambda hardware: dict(hardware.joint_positions()))
        head = head_angles_towards(kinematics, joints, target)
        aim = within_head_limits({**head, "head_1_joint": head["head_1_joint"] + pan_offset})
        run.follow(move_joints(aim), span=(0.0, 0.15))
        try:
            return look(run)
        except ActionAbort as abort:
            if abort.code != ErrorCodes.MARKER_NOT_FOUND:
                raise
            failure = abort
    assert failure is not None
    raise failure


def working_pose(station: Station, sub_position: int, arm: str) -> np.ndarray:
    """T_world_base where the robot works at nest ``sub_position`` (`station_placement.nest_working_pose`:
    the station's working pose, moved along the bench to keep the nest inside the arm's band)."""
    T_world_work = nest_working_pose(station, sub_position, arm)
    moved = tf.invert(station.aligned_pose().matrix()) @ T_world_work
    if abs(moved[1, 3]) > 1e-9:
        log.info(
            "nest %d of %s: working from %.3f m further %s, to keep it inside the %s arm's band",
            sub_position, station.name, abs(moved[1, 3]), "left" if moved[1, 3] > 0 else "right", arm,
        )  # fmt: skip
    return T_world_work


def align_base(
    run: GoalRun,
    station: Station,
    kinematics: RobotKinematics,
    look: Any,
    working_joints: dict[str, float],
    T_world_work: np.ndarray,
) -> Any:
    """Look at the marker, drive to the working pose it implies, look again; returns the last sighting.

    `look(run)` takes an image and returns the marker sighting (T_base_marker); the torso's target
    in `working_joints` (the bench working posture) is reached while the base drives, and the head
    turns to where the marker will be;
    `T_world_work` is the nominal working pose (`working_pose`).
    """
    # Where the base believes it stands (localisation), not the POI: a task may start where the
    # last one ended, at the working pose 0.22 m nearer.
    believed = run.read(lambda hardware: tuple(hardware.pose_estimate()))
    T_base_marker_expected = tf.invert(tf.from_planar(*believed)) @ station.T_world_marker()
    # The torso starts rising at once (it is the slowest joint); the image is taken with the joint
    # readings of the same instant, so the camera pose stays exact while it moves.
    torso = {name: value for name, value in working_joints.items() if name not in HEAD_JOINTS}
    lifting = run.read(move_joints(torso)) if torso else None
    background: list[Execution | None] = [lifting]  # motions running beside the ones this goal follows
    try:
        sighting = search_marker(run, kinematics, T_base_marker_expected[:3, 3], look, lifting)
        T_marker_work = tf.invert(station.T_world_marker()) @ T_world_work
        correction = planar(sighting.T_base_marker @ T_marker_work)  # working pose in base_footprint
        # The goal is fixed in the odometry frame (where the base stood at the sighting): the
        # hardware holds it there whatever localisation corrects meanwhile.
        goal_in_odom = tf.compose_planar(sighting.odometry, correction)

        log.info(
            "aligning at %s: working pose at x %.3f y %.3f m, yaw %.1f deg from here",
            station.name, correction[0], correction[1], math.degrees(correction[2]),
        )  # fmt: skip
        # From the working pose the marker is where the first sighting puts it: the head turns there
        # while the base drives (the torso's target height in the aim), so the look after the drive
        # needs no head move of its own (it took 0.3 to 0.6 s after the drive). The bench posture's
        # fixed head angles see a marker beside the nests of the default lab only: a marker 0.37 m
        # right of the base was out of the image, MARKER_NOT_FOUND with nothing disturbed.
        T_marker_at_work = tf.invert(tf.from_planar(*correction)) @ sighting.T_base_marker
        at_work = {**run.read(lambda hardware: dict(hardware.joint_positions())), **torso}
        head_at_marker = head_aim(kinematics, at_work, T_marker_at_work[:3, 3])
        turning = run.read(move_joints(head_at_marker))
        background.append(turning)
        run.follow(lambda hardware: hardware.drive_to(goal_in_odom, ALIGN_SPEED), span=(0.2, 0.9))
        for execution, span in ((lifting, (0.9, 0.95)), (turning, (0.95, 1.0))):
            if execution is not None:
                run.follow(execution, span=span)
        # from the working pose: later tool moves reuse this sighting while the base stands
        return search_marker(run, kinematics, T_marker_at_work[:3, 3], look, None)
    except BaseException:
        # A cancel or a failure stops the torso and the head too: the robot reported standing
        # still while its torso rose on (a cancel during the search, at 1x real time).
        run.stop(background)
        raise
