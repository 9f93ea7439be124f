"""Where a plate lies in its nest before a pick, read from a rendered depth image (pick_correction).

The scene: a standing bench with a row of three nests at 0.15 m (a 6 mm rim about each pocket) and a
plate in each, seen from a head camera 0.75 m away, as the TIAGo's sees a row from its working pose.
The robot believes the middle nest a few millimetres and a few tenths of a degree off the truth (the
marker's view and the nest's mounting); the plate lies off its nest's centre within the pocket. What
the pick needs is the plate in the frame the robot believes: the two errors together.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from labware_model.labware import LabwareType
from tests.tiago_skills.perception.bench_scene import box, nest_rims, rendered_depth
from tiago_description import transforms as tf
from tiago_sim.physics.camera import CameraIntrinsics
from tiago_skills.pick_correction import NEST_EMPTY, NEST_NOT_IN_VIEW, NOT_BELIEVED, plate_in_nest

PLATE = LabwareType("sbs", 0.12776, 0.08548, 0.01435, 0.35)
DEEP = LabwareType("deep", 0.12776, 0.08548, 0.0441, 0.45)
T_WORLD_SITE = tf.from_xyz_rpy((0.6, -0.25, 0.90), (0.0, 0.0, -np.pi / 2))
EYE = np.array([0.05, 0.0, 1.35])
PITCH = 0.15
DEPTH_NOISE_M = 0.002
BELIEF = tf.from_planar(0.004, -0.006, math.radians(0.6))  # the nest as believed, in the true one


def _render(plate: LabwareType | None, pose=(0.0, 0.0, 0.0), look_away: bool = False):
    """Depth image (with noise) and T_world_optical; `pose`: the middle plate's (x, y, yaw) in its nest."""

    def draw(client: int) -> None:
        box(client, (0.7, 1.0, 0.05), T_WORLD_SITE @ tf.make_transform((0, 0, -0.025)))
        for nest in (-1, 0, 1):
            T_world_nest = T_WORLD_SITE @ tf.make_transform((nest * PITCH, 0.0, 0.0))
            nest_rims(client, T_world_nest)
            held = plate if nest == 0 else PLATE  # the neighbours hold microplates
            if held is None:
                continue
            T_nest_plate = tf.from_planar(*pose) if nest == 0 else np.eye(4)
            centre = T_world_nest @ T_nest_plate @ tf.make_transform((0.0, 0.0, held.height / 2))
            box(client, (held.length, held.width, held.height), centre)

    target = T_WORLD_SITE[:3, 3] + ([0.0, 0.9, 0.0] if look_away else [0.0, 0.0, 0.0])
    return rendered_depth(draw, EYE, target, DEPTH_NOISE_M, seed=11)


def _seen(plate: LabwareType | None, pose=(0.0, 0.0, 0.0), look_away: bool = False):
    depth, T_world_optical = _render(plate, pose, look_away)
    T_believed_optical = tf.invert(T_WORLD_SITE @ BELIEF) @ T_world_optical
    return plate_in_nest(depth, CameraIntrinsics(), T_believed_optical, [PLATE, DEEP])


@pytest.mark.parametrize("plate", [PLATE, DEEP], ids=["microplate", "deep-well"])
@pytest.mark.parametrize(
    "pose", [(0.0, 0.0, 0.0), (0.0015, -0.0012, math.radians(-0.5))], ids=["centred", "off"]
)
def test_the_plate_is_found_where_it_lies_in_the_frame_believed(plate: LabwareType, pose) -> None:
    seen, why = _seen(plate, pose)
    assert seen is not None, why
    relative = tf.invert(BELIEF) @ tf.from_planar(*pose)
    truth = (relative[0, 3], relative[1, 3], tf.yaw_of(relative))
    # within what the open fingers leave a side (2.3 mm), with depth noise of 2 mm a pixel; a turn of
    # 0.5 deg moves the pads' ends 0.3 mm
    assert math.hypot(seen[0] - truth[0], seen[1] - truth[1]) < 0.002, (seen, truth, why)
    assert abs(seen[2] - truth[2]) < math.radians(0.5), (seen, truth, why)


def test_an_empty_nest_between_full_ones_has_no_plate_to_pick() -> None:
    assert _seen(None) == (None, NEST_EMPTY)


def test_a_nest_out_of_view_says_so() -> None:
    assert _seen(PLATE, look_away=True) == (None, NEST_NOT_IN_VIEW)


def test_a_plate_further_off_than_errors_make_is_not_believed() -> None:
    """A plate 18 mm off its nest's centre is not in its pocket: something else is wrong."""
    seen, why = _seen(PLATE, (0.0, 0.012, 0.0))
    assert seen is None and why.startswith(NOT_BELIEVED) or why.startswith("no plate type fits"), why
