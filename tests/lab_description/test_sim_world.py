"""World YAML loading and validation; the generated robot model in pinocchio."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from lab_description.station_placement import nest_working_poses
from lab_description.world import DEFAULT_WORLD, WorldError, load_world
from labware_model.holders import Nest
from labware_model.labware import Plate
from labware_model.workcell import StationDescription
from tiago_description import robot_model
from tiago_description import transforms as tf
from tiago_description.kinematics import forward


def test_default_world_loads_with_two_distant_stations_a_dock_and_a_plate():
    world = load_world()
    assert [s.name for s in world.stations] == ["station_a", "station_b"]
    a, b = world.stations
    distance = np.linalg.norm(a.T_world_site(1)[:2, 3] - b.T_world_site(1)[:2, 3])
    assert distance >= 3.0
    assert world.dock_poi in world.pois and a.poi in world.pois and b.poi in world.pois
    assert dict(world.plates) == {Plate("plate_001", "sbs_microplate_96"): Nest("station_a", 1)}
    plate = world.labware_types["sbs_microplate_96"]
    assert (plate.length, plate.width, plate.height) == (0.12776, 0.08548, 0.01435)
    for station in world.stations:
        assert station.marker_id not in (8, 9, 17, 47) and station.marker_size >= 0.10


def test_the_world_names_nests_plates_and_the_workcell_in_the_labware_model():
    world = load_world()
    assert world.station("station_b").nests() == (Nest("station_b", 1), Nest("station_b", 2))
    workcell = world.describe_workcell()
    assert workcell.stations == (
        StationDescription("station_a", 2, "station_a_work"),
        StationDescription("station_b", 2, "station_b_work"),
    )
    assert workcell.hotel_slots == 2 and workcell.dock_poi == world.dock_poi
    assert workcell.pois == tuple(sorted(world.pois))


SHIPPED_WORLDS = sorted(DEFAULT_WORLD.parent.glob("*.yaml"))


@pytest.mark.parametrize("world_file", SHIPPED_WORLDS, ids=[path.stem for path in SHIPPED_WORLDS])
def test_work_poi_stands_in_front_of_the_nests_facing_them(world_file):
    world = load_world(world_file)
    for station in world.stations:
        T_world_poi = world.pois[station.poi].matrix()
        for sub, T_world_base in nest_working_poses(station):
            T_poi_site = tf.invert(T_world_poi) @ station.T_world_site(sub)
            assert 0.55 <= T_poi_site[0, 3] <= 0.80  # the POI: behind the working pose (0.45 .. 0.55)
            T_base_site = tf.invert(T_world_base) @ station.T_world_site(sub)
            # worked at from within the right arm's band: 0 .. 0.45 m right of the base
            assert -0.45 - 1e-9 <= T_base_site[1, 3] <= 1e-9
            assert T_base_site[2, 3] == pytest.approx(station.table_size[2])


def _write(tmp_path: Path, mutate) -> Path:
    data = yaml.safe_load(DEFAULT_WORLD.read_text())
    mutate(data)
    path = tmp_path / "world.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize(
    ("mutate", "field", "problem"),
    [
        (lambda d: d["stations"][1]["marker"].update(id=17), "stations[1].marker.id", "mirrored"),
        (lambda d: d["stations"][0]["marker"].update(size=0.05), "stations[0].marker.size", "outside"),
        (lambda d: d["stations"][0]["table"].pop("pose"), "stations[0].table.pose", "missing"),
        (
            lambda d: d["stations"][0]["nests"].update(sub_positions="two"),
            "stations[0].nests.sub_positions",
            "integer",
        ),
        (lambda d: d["plates"][0].update(station="nowhere"), "plates[0].station", "unknown station"),
        (
            lambda d: d["plates"].append({**d["plates"][0], "id": "plate_002"}),
            "plates[1]",
            "('station_a', 1) already holds a plate",
        ),
        (
            lambda d: d["plates"].append({"id": "plate_001", "type": "sbs_microplate_96", "hotel_slot": 2}),
            "plates[1].id",
            "duplicate plate id",
        ),
        (lambda d: d["stations"][1].update(name="station_a"), "stations[1].name", "duplicate"),
        (lambda d: d["dock"].update(pose=[1, 2]), "dock.pose", "list of 3 numbers"),
    ],
)
def test_bad_world_file_is_reported_with_file_and_field(tmp_path, mutate, field, problem):
    path = _write(tmp_path, mutate)
    with pytest.raises(WorldError) as caught:
        load_world(path)
    message = str(caught.value)
    assert str(path) in message and field in message and problem in message


def test_unparsable_world_file_names_the_file(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("stations: [unclosed\n")
    with pytest.raises(WorldError, match="broken.yaml"):
        load_world(path)


def test_moving_a_station_is_a_yaml_edit(tmp_path):
    path = _write(tmp_path, lambda d: d["stations"][0]["table"].update(pose=[3.0, -2.0, 45.0]))
    world = load_world(path)
    station = world.station("station_a")
    site = station.T_world_site(1)
    T_base_site = tf.invert(world.pois[station.poi].matrix()) @ site
    assert math.degrees(world.pois[station.poi].yaw) == pytest.approx(45.0)
    assert T_base_site[0, 3] == pytest.approx(0.72, abs=1e-6)  # navigation stops at the standoff
    T_work_site = tf.invert(station.aligned_pose().matrix()) @ site
    assert T_work_site[0, 3] == pytest.approx(0.5, abs=1e-6)  # the final approach ends at work_standoff


def test_head_camera_and_arm_frames_match_the_tiago_figures():
    camera = forward({}, "head_front_camera_rgb_optical_frame")
    np.testing.assert_allclose(camera[:3, 3], [0.216, 0.022, 1.067], atol=1e-3)
    # OpenCV optical frame: z forward (base x), x right (base -y), y down (base -z)
    np.testing.assert_allclose(camera[:3, :3], [[0, 0, 1], [-1, 0, 0], [0, -1, 0]], atol=1e-9)
    lifted = forward({"torso_lift_joint": 0.2}, "head_front_camera_rgb_optical_frame")
    assert lifted[2, 3] == pytest.approx(1.267, abs=1e-3)
    right = forward({}, "arm_right_1_link")
    left = forward({}, "arm_left_1_link")
    np.testing.assert_allclose(right[:3, 3], [-0.03644, -0.19, 0.7175], atol=1e-4)
    np.testing.assert_allclose(left[:3, 3] * [1, -1, 1], right[:3, 3], atol=1e-4)


def test_urdf_declares_the_joint_limits_of_the_table():
    text = robot_model.build_urdf()
    assert 'name="torso_lift_joint" type="prismatic"' in text
    for side in robot_model.ARM_SIDES:
        for name in robot_model.arm_joint_names(side) + robot_model.finger_joint_names(side):
            assert f'name="{name}"' in text
        assert f'name="gripper_{side}_grasping_frame"' in text
    assert 'name="hotel_slot_1"' in text and 'name="hotel_slot_2"' in text
