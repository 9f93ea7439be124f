"""Before a pick: where the plate lies in its nest, seen by the head camera, and the move of the nest
frame onto it (robot software).

Why: the fingers reach the nest the marker shows, and a nest stands off the marker by what the lab's
fitters left: a row's turn of 0.63 deg put the sixth nest of a row, 1.06 m from its marker, 7.5 mm
across from where the robot believed it (random layout 202052). The open fingers leave 2.3 mm a side
on a plate's short side; they closed on its edge and pinched it against the nest, and it slipped
out of the grip. The plate itself is what the fingers must meet, so it is measured: its top's
pixels in the depth image give its centre and its turn in the nest frame
(``tiago_skills.perception.held_plate`` with no pads in the way), and the grasp goes there. The
plate and the marker need not share one image: the pick's target is the plate as the camera sees it
in base_footprint, the site frame only carries it.

Only the head camera's depth image and joint readings are used, as on the real robot.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

from labware_model.labware import LabwareType
from robot_port.types import CameraIntrinsics
from tiago_description import transforms as tf
from tiago_skills.perception.held_plate import HeldPlateSighting, locate_held_plate, site_points
from tiago_skills.perception.nest_occupancy import view_points
from tiago_skills.place_correction import MAX_SHIFT_M, MAX_TURN_RAD

# Pixels are read this far beyond a plate's outline about the nest's centre: a plate lies up to its
# pocket's clearance and the nest's mounting error (about 8 mm) off it, and a neighbour's plate in a
# row at 0.15 m stands 22 mm beyond a centred plate's end.
NEST_WINDOW_M = 0.012
# Why there is no measurement; the first two may change with the head aimed at the nest.
NEST_NOT_IN_VIEW = "the nest is not in the head camera's view"
PLATE_NOT_WHOLE = "no plate type fits the pixels in the nest (an edge out of view?)"
NEST_EMPTY = "no plate in the nest"
NOT_BELIEVED = "the plate lies further off the nest than its clearance and mounting errors make"
LOOK_AT_NEST = (NEST_NOT_IN_VIEW, PLATE_NOT_WHOLE)


def plate_in_nest(
    depth: np.ndarray,
    intrinsics: CameraIntrinsics,
    T_site_optical: np.ndarray,
    plate_types: Iterable[LabwareType],
) -> tuple[tf.Planar | None, str]:
    """The plate's pose (x, y, yaw) in the nest's site frame as the camera sees it at
    ``T_site_optical``, and a description of it; or None and why not."""
    types = list(plate_types)
    points = site_points(depth, intrinsics, T_site_optical)  # once, for both reads
    view = view_points(points, [(t.length, t.width, t.height) for t in types])
    if not view.seen:
        return None, NEST_NOT_IN_VIEW
    if not view.occupied:
        return None, NEST_EMPTY
    found: HeldPlateSighting | None = None
    for plate in sorted(types, key=lambda t: abs(t.height - view.height_m)):  # the type seen first
        found = _located(points, plate, np.zeros(3))
        if found is not None:  # read again about where it lies: its long sides' pixels are then left out
            found = _located(points, plate, np.array([found.x, found.y, 0.0])) or found
            break
    if found is None:
        return None, PLATE_NOT_WHOLE
    x, y, yaw = found.pose
    seen = f"({1000 * x:.1f}, {1000 * y:.1f}) mm, {math.degrees(yaw):.2f} deg from the nest"
    seen += f" ({found.points} pixels)"
    if math.hypot(x, y) > MAX_SHIFT_M or abs(yaw) > MAX_TURN_RAD:
        return None, f"{NOT_BELIEVED}: {seen}"
    return found.pose, seen


def _located(points: np.ndarray, plate: LabwareType, about: np.ndarray) -> HeldPlateSighting | None:
    """The plate of type ``plate`` resting in the nest, read about ``about`` (site frame)."""
    size = (plate.length, plate.width, plate.height)
    return locate_held_plate(points, about, 0.0, *size, pad_width=0.0, window_m=NEST_WINDOW_M)
