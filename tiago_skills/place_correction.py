"""Before a held plate goes down into a nest: where it hangs, seen by the head camera, and the shift of
the tool (a move and a turn) that puts it on the nest (robot software).

Why: the tool reaches the nest the marker shows, but the plate hangs in the hand where the hotel's
pocket and the fingers left it, and the head camera's calibration error moves the nest the robot
sees; together they put plates 8 to 11 mm off the nest, past the 7.5 mm its ramps capture
(docs/explanation/decisions/measure-the-held-plate.md). The camera sees plate and marker with the same
error while the head stands where it stood when it saw the marker, so the plate's offset from the nest
it measures holds neither that error nor the arm's (``tiago_skills.perception.held_plate``). The shift is
then the planar move of the tool that brings the plate's centre over the nest's and its long side along
the nest's: from the tool's pose (joint readings) and the plate's (camera), both in the site frame the marker
gave. The turn is part of it since a plate turned 0.7 deg and 1.5 mm across left a corner on a
lead-in (default lab, a CI run of test_examples).

Only joint readings and the head camera's depth image are used, as on the real robot. Lives on the
marker motion's executor thread (the image and its joint readings come through the hardware port).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from labware_model.labware import LabwareType
from tiago_description import transforms as tf
from tiago_description.robot_model import PAD_WIDTH
from tiago_skills.perception.held_plate import HeldPlateSighting, locate_held_plate, site_points

log = logging.getLogger(__name__)

HEAD_JOINTS = ("head_1_joint", "head_2_joint")
# The head counts as unmoved since the marker sighting within this (rad): the camera's error is then the
# same in both images. That error (mount offset, encoder zeros) is constant; turning the head by
# 0.01 rad turns the few millimetres it makes at the nest by as much, a change of hundredths of a
# millimetre. A head still settling from its last aim moved 1 to 3 mrad between the two images,
# and a limit of 0.5 mrad skipped the measurement then.
SAME_HEAD_RAD = 0.01
# A larger shift is not believed: the measurement would have gone wrong (the nest's ramps capture
# 7.5 mm, calibration and mounting errors reach about 12 mm together at three sigma).
MAX_SHIFT_M = 0.015
# Nor a larger turn: more than the hotel's pocket lets a carried plate turn (1 to 4 deg) and the
# arm's heading error together.
MAX_TURN_RAD = math.radians(8.0)
# Why a shift is missing, when another look with the head aimed at marker and plate together may give it.
HEAD_MOVED = "the head moved since the marker was seen"
NOT_SEEN_WHOLE = "no plate type fits the pixels about the tool (an end hidden?)"
NOT_BELIEVED = "the shift is larger than calibration and grasp errors make"
LOOK_AGAIN = (HEAD_MOVED, NOT_SEEN_WHOLE)


def head_moved(joints_then: dict[str, float], joints_now: dict[str, float]) -> bool:
    """Whether a head joint turned since ``joints_then`` (unknown readings count as moved)."""
    return any(
        name not in joints_then
        or name not in joints_now
        or abs(joints_now[name] - joints_then[name]) > SAME_HEAD_RAD
        for name in HEAD_JOINTS
    )


def tool_heading(T_site_tool: np.ndarray) -> float:
    """Where a top-down tool faces in the site's plane: its z axis (the fingers' opening runs along its
    y, the approach along its x, straight down) projected on the nest plane; 0 for the nominal grasp
    (``HotelGrasp.T_slot_grasp``), pi for its twin."""
    return math.atan2(float(T_site_tool[1, 2]), float(T_site_tool[0, 2]))


def place_shift(
    capture: Callable[[], tuple[np.ndarray, Any, dict[str, float]]],
    forward: Callable[[dict[str, float], str], np.ndarray],
    T_base_site: np.ndarray,
    arm: str,
    camera_frame: str,
    sighting_joints: dict[str, float],
    plate_types: Iterable[LabwareType],
    plate_bottom_below_tool: float,
) -> tuple[tf.Planar | None, str]:
    """The planar move (x, y, yaw) of the site frame that makes the tool's place pose, taken in the
    moved frame, put the held plate centred and square on the nest, and "" ; or None and why it cannot
    be measured (HEAD_MOVED, NOT_SEEN_WHOLE, NOT_BELIEVED).

    The plate moves rigidly with the tool: if the tool went to the nominal pose G (heading 0 or pi, the
    twin it holds the plate with) the plate would land at G * inv(T) * P, T and P the tool's and the
    plate's planar poses in the site frame now; the site moved by the inverse of that lands it at the
    nest's centre, its long side along the nest's.

    ``capture`` returns the depth image, its intrinsics and the joint readings taken with it;
    ``forward`` is the robot model's forward kinematics (T_base_frame of a frame for joint readings).
    """
    depth, intrinsics, joints = capture()
    if head_moved(sighting_joints, joints):
        turned = {n: round(joints.get(n, 0.0) - sighting_joints.get(n, 0.0), 4) for n in HEAD_JOINTS}
        log.info("held plate not measured: %s (%s rad)", HEAD_MOVED, turned)
        return None, HEAD_MOVED
    T_site_base = tf.invert(T_base_site)
    points = site_points(depth, intrinsics, T_site_base @ forward(joints, camera_frame))
    T_site_tool = T_site_base @ forward(joints, f"gripper_{arm}_grasping_frame")
    tool = T_site_tool[:3, 3]
    sighting: HeldPlateSighting | None = None
    for plate in plate_types:
        sighting = locate_held_plate(
            points, tool, plate_bottom_below_tool, plate.length, plate.width, plate.height, PAD_WIDTH
        )
        if sighting is not None:
            break
    if sighting is None:
        log.info("held plate not measured: %s", NOT_SEEN_WHOLE)
        return None, NOT_SEEN_WHOLE
    heading = tool_heading(T_site_tool)
    nominal = (0.0, 0.0, math.pi * round(heading / math.pi))
    in_hand = tf.compose_planar(tf.invert_planar((float(tool[0]), float(tool[1]), heading)), sighting.pose)
    shift = tf.invert_planar(tf.compose_planar(nominal, in_hand))
    log.info(
        "held plate at (%.1f, %.1f) mm, %.2f deg from the nest, tool at (%.1f, %.1f) mm (%d pixels, "
        "%.1f x %.1f mm): moving the place by (%.1f, %.1f) mm, %.2f deg",
        1000 * sighting.x, 1000 * sighting.y, math.degrees(sighting.yaw), 1000 * tool[0], 1000 * tool[1],
        sighting.points, 1000 * sighting.length, 1000 * sighting.width, 1000 * shift[0], 1000 * shift[1],
        math.degrees(shift[2]),
    )  # fmt: skip
    if math.hypot(shift[0], shift[1]) > MAX_SHIFT_M or abs(shift[2]) > MAX_TURN_RAD:
        log.warning(
            "move of %.1f mm, %.1f deg not believed: placing where the marker says",
            1000 * math.hypot(shift[0], shift[1]), math.degrees(shift[2]),
        )  # fmt: skip
        return None, NOT_BELIEVED
    return shift, ""
