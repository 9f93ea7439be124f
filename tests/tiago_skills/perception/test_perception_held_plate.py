"""The held plate's centre over its nest from a rendered depth image, and the place shift built on it.

The scene: a bench top, a plate hanging 0.1 m above a nest site at a known offset, the two finger pads
against the middle of its long sides and a palm above it, seen from a head camera 0.7 m away as the
TIAGo's looks down at a nest. The shift must be the tool's position minus the plate's even when the
robot's idea of its camera is off: the site frame comes through the same camera.
"""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest

from labware_model.labware import LabwareType
from tiago_description import transforms as tf
from tiago_description.motion_library import HotelGrasp
from tiago_description.robot_model import PAD_WIDTH
from tiago_sim.physics.camera import CameraIntrinsics, optical_frame_looking_at, render_rgbd
from tiago_skills.grasp_twins import FLIP_ABOUT_APPROACH
from tiago_skills.perception.held_plate import HeldPlateSighting, locate_held_plate, site_points
from tiago_skills.place_correction import HEAD_MOVED, place_shift

PLATE = LabwareType("sbs", 0.12776, 0.08548, 0.01435, 0.35)
GRASP_HEIGHT = 0.012  # grasping frame above the plate's bottom
APPROACH = 0.10  # plate bottom above the nest floor
# The nest's site frame in the world: on a bench 0.75 m high, x (the plate's long side) to the left.
T_WORLD_SITE = tf.from_xyz_rpy((0.6, -0.05, 0.75), (0.0, 0.0, -np.pi / 2))
EYE = np.array([0.05, 0.0, 1.3])


def _box(client: int, size, T_world_centre: np.ndarray, rgba=(0.8, 0.5, 0.2, 1)) -> int:
    half = [s / 2 for s in size]
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=rgba, physicsClientId=client)
    position, quat = tf.to_pose(T_world_centre)
    return p.createMultiBody(0, shape, visual, position, quat, physicsClientId=client)


def _render(
    plate_xy: tuple[float, float],
    tool_xy: tuple[float, float],
    hide_left_end: bool = False,
    tilt_deg: float = 0.0,
    yaw_deg: float = 0.0,
    cut_corner: bool = False,
):
    """Depth image of the scene and T_world_optical; tool and plate offsets in the site frame (m)."""
    client = p.connect(p.DIRECT)
    try:
        _box(client, (0.7, 1.0, 0.05), T_WORLD_SITE @ tf.make_transform((0, 0, -0.025)), (0.7, 0.7, 0.6, 1))
        bottom = APPROACH
        plate_centre = (plate_xy[0], plate_xy[1], bottom + PLATE.height / 2)
        # turned about the nest's z (with the hand), tilted about the fingers' axis
        tilt = tf.from_xyz_rpy(plate_centre, (0.0, np.radians(tilt_deg), np.radians(yaw_deg)))
        _box(client, (PLATE.length, PLATE.width, PLATE.height), T_WORLD_SITE @ tilt)
        tool_z = bottom + GRASP_HEIGHT
        for side in (-1, 1):  # pads outside the long sides, 80 mm wide, from 5 mm below the tool upwards
            pad_y = plate_xy[1] + side * (PLATE.width / 2 + 0.005)
            centre = (tool_xy[0], pad_y, tool_z + 0.0125)
            _box(client, (0.08, 0.01, 0.035), T_WORLD_SITE @ tf.make_transform(centre), (0.1, 0.2, 0.7, 1))
        palm = (tool_xy[0], tool_xy[1], tool_z + 0.06)
        _box(client, (0.05, 0.11, 0.04), T_WORLD_SITE @ tf.make_transform(palm), (0.3, 0.3, 0.3, 1))
        if hide_left_end:  # an arm link between the camera and the plate's +x end
            hider = (PLATE.length / 2 - 0.005, -0.025, bottom + 0.04)
            _box(client, (0.05, 0.15, 0.02), T_WORLD_SITE @ tf.make_transform(hider), (0.3, 0.3, 0.3, 1))
        if cut_corner:  # an arm link across the +x end at 45 deg, hiding a corner of it
            link = tf.from_xyz_rpy((PLATE.length / 2 - 0.005, 0.025, bottom + 0.04), (0.0, 0.0, np.pi / 4))
            _box(client, (0.07, 0.02, 0.015), T_WORLD_SITE @ link, (0.3, 0.3, 0.3, 1))
        T_world_optical = optical_frame_looking_at(EYE, T_WORLD_SITE[:3, 3] + [0.0, 0.0, 0.1])
        _rgb, depth = render_rgbd(client, T_world_optical, CameraIntrinsics())
        return depth, T_world_optical
    finally:
        p.disconnect(client)


@pytest.mark.parametrize("plate_xy", [(0.0, 0.0), (0.009, -0.004), (-0.006, 0.003)])
def test_the_plate_centre_is_found_within_a_millimetre(plate_xy):
    _assert_found_within_a_millimetre(plate_xy, (0.002, 0.001))


def _assert_found_within_a_millimetre(plate_xy, tool_xy, tilt_deg: float = 0.0) -> None:
    depth, T_world_optical = _render(plate_xy, tool_xy, tilt_deg=tilt_deg)
    points = site_points(depth, CameraIntrinsics(), tf.invert(T_WORLD_SITE) @ T_world_optical)
    tool = np.array([*tool_xy, APPROACH + GRASP_HEIGHT])
    sighting = locate_held_plate(
        points, tool, GRASP_HEIGHT, PLATE.length, PLATE.width, PLATE.height, PAD_WIDTH
    )
    assert sighting is not None
    assert abs(sighting.x - plate_xy[0]) < 0.001
    assert abs(sighting.y - plate_xy[1]) < 0.001


def _sighting_held_at(
    plate_xy: tuple[float, float], yaw_deg: float, cut_corner: bool = False
) -> HeldPlateSighting:
    """The plate found with the tool at (2, 1) mm from the site, the plate at ``plate_xy`` turned."""
    tool_xy = (0.002, 0.001)
    depth, T_world_optical = _render(plate_xy, tool_xy, yaw_deg=yaw_deg, cut_corner=cut_corner)
    points = site_points(depth, CameraIntrinsics(), tf.invert(T_WORLD_SITE) @ T_world_optical)
    tool = np.array([*tool_xy, APPROACH + GRASP_HEIGHT])
    sighting = locate_held_plate(
        points, tool, GRASP_HEIGHT, PLATE.length, PLATE.width, PLATE.height, PAD_WIDTH
    )
    assert sighting is not None
    return sighting


@pytest.mark.parametrize(
    ("plate_xy", "yaw_deg"), [((0.002, 0.001), 1.0), ((0.004, -0.002), -1.5), ((0.0, 0.0), 3.0)]
)
def test_a_plate_turned_in_the_hand_is_found_with_its_turn(plate_xy, yaw_deg):
    """A carried plate hangs turned by a degree or more (default lab, 1.44 deg at station_a/1 in
    test_examples, 0.74 deg with 1.5 mm across in a failed CI run: a corner left on a lead-in). Its
    turn is read within 0.5 deg (0.22 deg RMS over 28 poses of plate and tool: the edges' pixels are
    1.3 mm apart at 0.7 m), its centre still within 1 mm."""
    sighting = _sighting_held_at(plate_xy, yaw_deg)
    assert abs(np.degrees(sighting.yaw) - yaw_deg) < 0.5
    assert abs(sighting.x - plate_xy[0]) < 0.001
    assert abs(sighting.y - plate_xy[1]) < 0.001


@pytest.mark.parametrize("yaw_deg", [-1.7, 1.2])
def test_the_turn_is_read_with_a_corner_of_the_plate_hidden(yaw_deg: float):
    """Default lab, station_b/2: an arm link crossed one end of the held plate diagonally, the ends
    were not two parallel lines, and the plate went down 1.2 deg turned, unmeasured. Each edge's
    straightest stretch still gives the turn."""
    sighting = _sighting_held_at((0.002, 0.001), yaw_deg, cut_corner=True)
    assert abs(np.degrees(sighting.yaw) - yaw_deg) < 0.5


@pytest.mark.parametrize("tilt_deg", [-4.0, 2.0, 4.0])
def test_a_plate_tilted_in_the_hand_is_found_within_a_millimetre(tilt_deg):
    """Carried plates turn a few degrees about the fingers' axis (random layouts 75083, 75185): a level
    band about the top's median height cut off both ends, and the plate went down unmeasured."""
    _assert_found_within_a_millimetre((0.005, -0.003), (0.0, 0.0), tilt_deg)


def test_a_plate_with_an_end_hidden_gives_no_measurement():
    depth, T_world_optical = _render((0.004, 0.0), (0.0, 0.0), hide_left_end=True)
    points = site_points(depth, CameraIntrinsics(), tf.invert(T_WORLD_SITE) @ T_world_optical)
    tool = np.array([0.0, 0.0, APPROACH + GRASP_HEIGHT])
    assert (
        locate_held_plate(points, tool, GRASP_HEIGHT, PLATE.length, PLATE.width, PLATE.height, PAD_WIDTH)
        is None
    )


@pytest.mark.parametrize(("yaw_deg", "flipped"), [(0.0, False), (1.3, False), (-1.2, True)])
def test_the_place_shift_is_free_of_the_camera_calibration_error(yaw_deg: float, flipped: bool):
    """The robot's camera frame is off by 2 mm and 0.2 deg, so the nest it sees is off by several mm;
    plate and nest are seen through that same frame, so the moved tool puts the plate on the nest,
    square to it when it hung turned in the hand (whichever of the twin grasps holds it)."""
    plate_xy, tool_xy = (0.008, -0.003), (0.001, 0.002)
    depth, T_world_optical = _render(plate_xy, tool_xy, yaw_deg=yaw_deg)
    error = tf.from_xyz_rpy((0.002, -0.001, 0.001), np.radians([0.2, -0.1, 0.2]))
    T_base_optical_believed = T_world_optical @ tf.invert(error)  # the robot's model of its camera
    # the marker seen through the believed camera: the site lands off by the camera's error
    T_base_site_believed = T_base_optical_believed @ tf.invert(T_world_optical) @ T_WORLD_SITE
    assert np.linalg.norm(T_base_site_believed[:2, 3] - T_WORLD_SITE[:2, 3]) > 0.003
    grasp = HotelGrasp(GRASP_HEIGHT, 0.0).T_slot_grasp(approach=False) @ (
        FLIP_ABOUT_APPROACH if flipped else np.eye(4)
    )
    T_base_tool = T_WORLD_SITE @ tf.make_transform((*tool_xy, APPROACH)) @ grasp
    frames = {
        "head_front_camera_rgb_optical_frame": T_base_optical_believed,
        "gripper_right_grasping_frame": T_base_tool,
    }
    joints = {"head_1_joint": 0.1, "head_2_joint": -0.9}
    shift, _why = place_shift(
        lambda: (depth, CameraIntrinsics(), joints),
        lambda _joints, frame: frames[frame],
        T_base_site_believed,
        "right",
        "head_front_camera_rgb_optical_frame",
        dict(joints),
        [PLATE],
        GRASP_HEIGHT,
    )
    assert shift is not None
    T_base_tool_at_place = T_base_site_believed @ tf.from_planar(*shift) @ grasp
    in_hand = tf.invert(T_base_tool) @ T_WORLD_SITE @ tf.from_planar(*plate_xy, np.radians(yaw_deg), APPROACH)
    plate_in_site = tf.invert(T_WORLD_SITE) @ T_base_tool_at_place @ in_hand
    np.testing.assert_allclose(plate_in_site[:2, 3], [0.0, 0.0], atol=0.001)
    assert abs(np.degrees(tf.yaw_of(plate_in_site))) < 0.5


@pytest.mark.parametrize(
    ("pan_then", "measured"),
    [(0.1 + 0.05, False), (0.1 + 0.003, True)],  # re-aimed; still settling from the last aim (96000)
    ids=["turned", "settling"],
)
def test_no_shift_once_the_head_has_turned_but_one_while_it_settles(pan_then: float, measured: bool):
    depth, T_world_optical = _render((0.0, 0.0), (0.0, 0.0))
    T_world_tool = T_WORLD_SITE @ tf.make_transform((0.0, 0.0, APPROACH + GRASP_HEIGHT))
    frames = {
        "head_front_camera_rgb_optical_frame": T_world_optical,
        "gripper_right_grasping_frame": T_world_tool,
    }
    shift, why = place_shift(
        lambda: (depth, CameraIntrinsics(), {"head_1_joint": 0.1, "head_2_joint": -0.9}),
        lambda _joints, frame: frames[frame],
        T_WORLD_SITE,
        "right",
        "head_front_camera_rgb_optical_frame",
        {"head_1_joint": pan_then, "head_2_joint": -0.9},
        [PLATE],
        GRASP_HEIGHT,
    )
    assert (shift is not None) == measured
    assert why == ("" if measured else HEAD_MOVED)


@pytest.mark.parametrize("tool_off", [-0.012, -0.009, 0.009, 0.012])
def test_the_pads_are_left_out_where_the_camera_sees_them_not_only_where_the_arm_says(tool_off: float):
    """Random layout 99012: the arm's joint readings put the tool 7 mm along the plate from where the
    camera saw the pads (calibration errors of camera and arm); the pads' outer faces were taken for
    the plate's long sides (95 mm wide against 85.5), the place went unmeasured and the plate landed on
    a lead-in's rim (the rendered pads here show from 9 mm). The plate is still found, its centre
    within a millimetre."""
    plate_xy = (0.002, -0.001)
    depth, T_world_optical = _render(plate_xy, (0.0, 0.0))  # the pads about (0, 0) in the image
    points = site_points(depth, CameraIntrinsics(), tf.invert(T_WORLD_SITE) @ T_world_optical)
    tool = np.array([tool_off, 0.0, APPROACH + GRASP_HEIGHT])  # where the arm's readings put it
    sighting = locate_held_plate(
        points, tool, GRASP_HEIGHT, PLATE.length, PLATE.width, PLATE.height, PAD_WIDTH
    )
    assert sighting is not None
    assert abs(sighting.x - plate_xy[0]) < 0.001
    assert abs(sighting.y - plate_xy[1]) < 0.001
