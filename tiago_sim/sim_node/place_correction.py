"""Before a held plate goes down into a nest: where it hangs, seen by the head camera, and the shift of
the tool that puts it on the nest (robot software).

Why: the tool reaches the nest the marker shows, but the plate hangs in the hand where the hotel's
pocket and the fingers left it, and the head camera's calibration error moves the nest the robot
sees; together they put plates 8 to 11 mm off the nest, past the 7.5 mm its ramps capture (default
lab, seeds 60000, 60034, 60077). The camera sees plate and marker with the same error while the head
stands where it stood when it saw the marker, so the plate's offset from the nest it measures holds
neither that error nor the arm's (``tiago_sim.perception.held_plate``). The shift is then what the
tool must move so that the plate's centre comes over the nest's: the tool's position (joint readings)
minus the plate's (camera), both in the site frame the marker gave.

Only joint readings and the head camera's depth image are used, as on the real robot. Lives on the
marker motion's executor thread (the image and the joints are taken on the sim thread).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from labware_model.labware import LabwareType
from tiago_sim import transforms as tf
from tiago_sim.perception.held_plate import HeldPlateSighting, locate_held_plate, site_points
from tiago_sim.robot.robot_model import PAD_WIDTH

log = logging.getLogger(__name__)

HEAD_JOINTS = ("head_1_joint", "head_2_joint")
# The head counts as unmoved since the marker sighting within this (rad): the camera's error is then the
# same in both images. That error (mount offset, encoder zeros) is constant; turning the head by
# 0.01 rad turns the few millimetres it makes at the nest by as much, a change of hundredths of a
# millimetre. A head still settling from its last aim moved 1 to 3 mrad between the two images,
# and 0.5 mrad skipped the measurement then (default-lab seeds 96000, 96015 at 591b7bc).
SAME_HEAD_RAD = 0.01
# A larger shift is not believed: the measurement would have gone wrong (the nest's ramps capture
# 7.5 mm, calibration and mounting errors reach about 12 mm together at three sigma).
MAX_SHIFT_M = 0.015


def head_moved(joints_then: dict[str, float], joints_now: dict[str, float]) -> bool:
    """Whether a head joint turned since ``joints_then`` (unknown readings count as moved)."""
    return any(
        name not in joints_then
        or name not in joints_now
        or abs(joints_now[name] - joints_then[name]) > SAME_HEAD_RAD
        for name in HEAD_JOINTS
    )


def place_shift(
    capture: Callable[[], tuple[np.ndarray, Any, dict[str, float]]],
    forward: Callable[[dict[str, float], str], np.ndarray],
    T_base_site: np.ndarray,
    arm: str,
    camera_frame: str,
    sighting_joints: dict[str, float],
    plate_types: Iterable[LabwareType],
    plate_bottom_below_tool: float,
) -> np.ndarray | None:
    """The (x, y) shift in the site frame to add to the tool's target so the held plate lands centred
    on the nest, or None when it cannot be measured (the head moved, the plate not seen whole).

    ``capture`` returns the depth image, its intrinsics and the joint readings taken with it;
    ``forward`` is the robot model's forward kinematics (T_base_frame of a frame for joint readings).
    """
    depth, intrinsics, joints = capture()
    if head_moved(sighting_joints, joints):
        turned = {n: round(joints.get(n, 0.0) - sighting_joints.get(n, 0.0), 4) for n in HEAD_JOINTS}
        log.info("held plate not measured: the head moved since the marker was seen (%s rad)", turned)
        return None
    T_site_base = tf.invert(T_base_site)
    points = site_points(depth, intrinsics, T_site_base @ forward(joints, camera_frame))
    tool = (T_site_base @ forward(joints, f"arm_{arm}_grasping_frame"))[:3, 3]
    sighting: HeldPlateSighting | None = None
    for plate in plate_types:
        sighting = locate_held_plate(
            points, tool, plate_bottom_below_tool, plate.length, plate.width, plate.height, PAD_WIDTH
        )
        if sighting is not None:
            break
    if sighting is None:
        log.info("held plate not measured: no plate type fits the pixels about the tool (an end hidden?)")
        return None
    shift = np.array([tool[0] - sighting.x, tool[1] - sighting.y])
    log.info(
        "held plate at (%.1f, %.1f) mm from the nest, tool at (%.1f, %.1f) mm (%d pixels, %.1f x %.1f mm): "
        "shifting the place by (%.1f, %.1f) mm",
        1000 * sighting.x, 1000 * sighting.y, 1000 * tool[0], 1000 * tool[1], sighting.points,
        1000 * sighting.length, 1000 * sighting.width, 1000 * shift[0], 1000 * shift[1],
    )  # fmt: skip
    if float(np.hypot(*shift)) > MAX_SHIFT_M:
        log.warning("shift of %.1f mm not believed: placing where the marker says", 1000 * np.hypot(*shift))
        return None
    return shift
