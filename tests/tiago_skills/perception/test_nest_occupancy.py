"""Whether a nest holds a plate, read from a rendered depth image as the head camera sees it.

The scene: a bench top with a nest (its floor the bench, a 6 mm rim around a plate's footprint),
seen from a head camera 0.75 m away looking down at it, as the TIAGo's does from its working pose.
The site frame the check gets comes from the robot's belief, a few millimetres off the truth.
"""

from __future__ import annotations

import numpy as np
import pytest

from labware_model.labware import LabwareType
from tests.tiago_skills.perception.bench_scene import RIM, box, nest_rims, rendered_depth
from tiago_description import transforms as tf
from tiago_sim.physics.camera import CameraIntrinsics
from tiago_skills.perception.nest_occupancy import view_nest

PLATE = LabwareType("sbs", 0.12776, 0.08548, 0.01435, 0.35)
LOW_PLATE = LabwareType("low", 0.12776, 0.08548, 0.0065, 0.2)
T_WORLD_SITE = tf.from_xyz_rpy((0.6, -0.25, 0.90), (0.0, 0.0, -np.pi / 2))  # a standing bench
EYE = np.array([0.05, 0.0, 1.35])
DEPTH_NOISE_M = 0.002  # per pixel at this distance: above the disturbance campaigns' 1.9 mm at 1 m


def _render(
    plate: LabwareType | None,
    *,
    plate_pose=(0.0, 0.0, 0.0, 0.0),
    cover: bool = False,
    look_away: bool = False,
):
    """Depth image (with noise) and T_world_optical; `plate_pose` (x, y, z of its bottom, tilt about
    its short side) in the site frame."""

    def draw(client: int) -> None:
        box(client, (0.7, 1.0, 0.05), T_WORLD_SITE @ tf.make_transform((0, 0, -0.025)))
        nest_rims(client, T_WORLD_SITE)
        if plate is not None:
            x, y, z, tilt = plate_pose
            centre = tf.from_xyz_rpy((x, y, z + plate.height / 2), (0.0, tilt, 0.0))
            box(client, (plate.length, plate.width, plate.height), T_WORLD_SITE @ centre)
        if cover:  # a tray held over the nest, hiding all of it
            box(client, (0.4, 0.4, 0.03), T_WORLD_SITE @ tf.make_transform((0, 0, 0.12)))

    target = T_WORLD_SITE[:3, 3] + ([0.0, 0.9, 0.0] if look_away else [0.0, 0.0, 0.0])
    return rendered_depth(draw, EYE, target, DEPTH_NOISE_M, seed=7)


def _view(depth: np.ndarray, T_world_optical: np.ndarray, belief_error=(0.004, -0.003, 0.002)):
    """The check with the site as the robot believes it (off the truth by `belief_error`, m)."""
    T_world_believed = T_WORLD_SITE @ tf.make_transform(belief_error)
    T_site_optical = tf.invert(T_world_believed) @ T_world_optical
    sizes = [(t.length, t.width, t.height) for t in (PLATE, LOW_PLATE)]
    return view_nest(depth, CameraIntrinsics(), T_site_optical, sizes)


def test_an_empty_nest_reads_empty():
    view = _view(*_render(None))
    assert view.occupied is False and not view.seated, view.reason
    assert abs(view.height_m) < 0.004


@pytest.mark.parametrize("plate", [PLATE, LOW_PLATE], ids=["sbs", "low"])
def test_a_seated_plate_reads_as_a_plate(plate):
    view = _view(*_render(plate))
    assert view.occupied is True and view.seated, view.reason
    assert abs(view.height_m - plate.height) < 0.004


@pytest.mark.parametrize("tilt_deg", [2.7, 4.0])
def test_a_plate_on_the_rim_is_a_plate_there_but_not_seated(tilt_deg: float):
    """A plate left with one end on a lead-in's rim is there all the same: the nest is not free for
    another plate; but it is not placed."""
    end_up = (PLATE.length / 2) * np.sin(np.radians(tilt_deg))
    view = _view(*_render(PLATE, plate_pose=(0.0, 0.0, end_up / 2, np.radians(tilt_deg))))
    assert view.occupied is True and not view.seated, view.reason


def test_a_nest_hidden_by_the_arm_gives_no_answer():
    view = _view(*_render(PLATE, cover=True))
    assert view.occupied is None
    assert "hides it" in view.reason


def test_a_nest_out_of_the_image_gives_no_answer():
    view = _view(*_render(None, look_away=True))
    assert view.occupied is None
    assert "depth pixels" in view.reason


def test_heights_count_from_the_floor_seen_before_not_the_one_believed():
    """The view stands 5 mm off (the camera's calibration): the floor seen empty before the place is
    the reference. A plate seated reads seated; one lying level on top of the rims, 6 mm up, not.
    (Whether the nest is empty is read against the floor believed: with SBS plates only, half
    their 14 mm leaves room for such a view; a 6.5 mm plate would not.)"""
    belief = (0.004, -0.003, -0.005)
    sizes = [(PLATE.length, PLATE.width, PLATE.height)]
    depth, T_world_optical = _render(None)
    T_site_optical = tf.invert(T_WORLD_SITE @ tf.make_transform(belief)) @ T_world_optical
    empty = view_nest(depth, CameraIntrinsics(), T_site_optical, sizes)
    assert empty.occupied is False and abs(empty.height_m - 0.005) < 0.002, empty.reason

    def seen(plate_bottom_m: float):  # noqa: ANN202
        depth, T_world_optical = _render(PLATE, plate_pose=(0.0, 0.0, plate_bottom_m, 0.0))
        T_site_optical = tf.invert(T_WORLD_SITE @ tf.make_transform(belief)) @ T_world_optical
        return view_nest(depth, CameraIntrinsics(), T_site_optical, sizes, floor_m=empty.height_m)

    assert seen(0.0).seated, seen(0.0).reason
    on_rims = seen(RIM)
    assert on_rims.occupied is True and not on_rims.seated, on_rims.reason
