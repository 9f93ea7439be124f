"""pinocchio FK/IK against the physics: the same URDF, the same frames, reachable nests and hotel slots."""

from __future__ import annotations

import numpy as np
import pytest

from lab_description.station_placement import nest_working_poses
from lab_description.world import DEFAULT_WORLD, load_world
from tests.helpers.tool_moves import KINEMATICS
from tiago_description import robot_model as rm
from tiago_description import transforms as tf
from tiago_description.kinematics import RobotKinematics, top_down_grasp
from tiago_sim.physics.simulation import Simulation

PLATE_HALF_HEIGHT = 0.01435 / 2
SHIPPED_WORLDS = sorted(DEFAULT_WORLD.parent.glob("*.yaml"))


@pytest.fixture(scope="module")
def kinematics() -> RobotKinematics:
    return RobotKinematics()


@pytest.mark.parametrize("world_file", SHIPPED_WORLDS, ids=[path.stem for path in SHIPPED_WORLDS])
def test_ik_reaches_every_nest_from_its_working_pose_and_both_hotel_slots(kinematics, world_file):
    """From where the marker-guided final approach parks the base for each nest (`work_standoff`,
    moved along the bench for a nest outside the arm's band), not from the POI where navigation stops
    (farther back, out of the hotel's sweep); in every shipped world."""
    world = load_world(world_file)
    seed = {
        "torso_lift_joint": 0.15,
        **dict(zip(rm.arm_joint_names("right"), (0.2, -1.1, -0.2, 1.94, -1.57, 1.37, 0.0), strict=True)),
    }
    targets = []
    for station in world.stations:
        for sub, T_world_base in nest_working_poses(station):
            T_base_site = tf.invert(T_world_base) @ station.T_world_site(sub)
            for lift in (0.0, station.approach_height):
                position = T_base_site[:3, 3] + [0, 0, PLATE_HALF_HEIGHT + lift]
                targets.append(top_down_grasp(position, tf.yaw_of(T_base_site)))
    for slot in (1, 2):
        T_base_slot = kinematics.forward({}, f"hotel_slot_{slot}")
        for lift in (0.0, 0.15):
            targets.append(top_down_grasp(T_base_slot[:3, 3] + [0, 0, PLATE_HALF_HEIGHT + lift], 0.0))
    flip = tf.make_transform(rotation=np.diag([1.0, -1.0, -1.0]))  # the same grasp, fingers swapped
    for index, wanted in enumerate(targets):
        for target in (wanted, wanted @ flip):  # as the skills and the loader: either finger order
            result = kinematics.inverse("right", target, seed, use_torso=True, seed=index)
            if result.success:
                break
        assert result.success, f"target {index} unreachable: {result}"
        q = dict(seed, **result.joint_positions)
        reached = kinematics.forward(q, "gripper_right_grasping_frame")
        assert np.linalg.norm(reached[:3, 3] - target[:3, 3]) < 1e-3
        assert tf.rotation_angle(reached[:3, :3], target[:3, :3]) < 3e-3
        for name, value in result.joint_positions.items():
            lower, upper = (
                kinematics.lower[kinematics.joint_index(name)],
                kinematics.upper[kinematics.joint_index(name)],
            )
            assert lower - 1e-9 <= value <= upper + 1e-9


def test_ik_reports_failure_for_a_target_out_of_reach(kinematics):
    result = kinematics.inverse(
        "right", top_down_grasp(np.array([1.6, 0.0, 0.8]), 0.0), {}, use_torso=True, restarts=5
    )
    assert not result.success and result.position_error_m > 0.1


def test_pinocchio_fk_matches_pybullet_link_poses():
    sim = Simulation(load_world(), seed=0)
    try:
        joints = sim.joint_positions()
        T_world_base = sim.robot.base_pose()
        for frame in (
            "head_front_camera_rgb_optical_frame",
            "gripper_right_grasping_frame",
            "gripper_left_grasping_frame",
            "hotel_slot_2",
        ):
            from_pinocchio = KINEMATICS.forward(joints, frame)
            from_physics = tf.invert(T_world_base) @ sim.robot.link_pose(frame)
            np.testing.assert_allclose(from_pinocchio, from_physics, atol=2e-4, err_msg=frame)
    finally:
        sim.close()
