"""Depth noise and calibration errors reach what the robot software computes, and only there.

The robot stands at station A's working pose looking at the marker (aimed from ground truth: test
set-up only). Each disturbance is applied alone, through disturbances.apply_to_simulation as a
campaign applies it, and the test compares what the robot software's own path gives (the wrapped
render, FK of joint readings with the nominal model) against the truth.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator

import numpy as np
import pybullet as p
import pytest

from lab_description.world import load_world
from tests.helpers.tool_moves import KINEMATICS
from tiago_description import robot_model as rm
from tiago_description import transforms as tf
from tiago_sim.measuring import disturbances
from tiago_sim.measuring.camera_noise import depth_sigma, noisy_depth
from tiago_sim.physics.arm_controller import SETTLE_TOLERANCE
from tiago_sim.physics.camera import render_rgbd
from tiago_sim.physics.simulation import Simulation
from tiago_skills.base_alignment import head_angles_towards
from tiago_skills.perception.aruco import detect_marker

CAMERA_FRAME = "head_front_camera_rgb_optical_frame"
STATION = "station_a"
SEED = 40010
MAX_MARKER_POSITION_ERROR_M = 0.003  # the perception error budget (README, benchmark targets)
MAX_MARKER_ANGLE_ERROR_DEG = 1.0
NO_DISTURBANCE = disturbances.DisturbanceLevels().scaled(0.0)
DEFAULT = disturbances.DisturbanceLevels()


@pytest.fixture
def sim_at_marker() -> Iterator[Simulation]:
    """A fresh robot at the working pose of STATION, its head pointed at the marker."""
    world = load_world()
    sim = Simulation(world, seed=5)
    try:
        station = world.station(STATION)
        goal = station.aligned_pose()
        sim.run(sim.undock())
        assert sim.run(sim.drive_to(goal.x, goal.y, goal.yaw)).success
        marker = (tf.invert(sim.robot.base_pose()) @ station.T_world_marker())[:3, 3]
        head = head_angles_towards(KINEMATICS, sim.joint_positions(), marker)
        assert sim.run(sim.move_joints(head)).success
        yield sim
    finally:
        sim.close()


def _apply(sim: Simulation, **levels: float) -> disturbances.TrialDisturbance:
    drawn = disturbances.draw(sim.world, SEED, dataclasses.replace(NO_DISTURBANCE, **levels))
    disturbances.apply_to_simulation(sim, drawn)
    return drawn


def _true_base_camera(sim: Simulation) -> np.ndarray:
    return tf.invert(sim.robot.base_pose()) @ sim.true_camera_pose()


def _believed_base_camera(sim: Simulation) -> np.ndarray:
    """What the robot software computes: FK of the joint readings in the nominal model."""
    return KINEMATICS.forward(sim.joint_positions(), CAMERA_FRAME)


def _pose_difference(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    return float(np.linalg.norm(a[:3, 3] - b[:3, 3])), math.degrees(tf.rotation_angle(a[:3, :3], b[:3, :3]))


def test_depth_noise_grows_with_distance_as_the_model_says_and_skips_empty_pixels():
    rng = np.random.default_rng(0)
    for distance in (0.5, 1.0, 2.0):
        plane = np.full((200, 200), distance, dtype=np.float32)
        noisy = noisy_depth(plane, DEFAULT.depth_noise_m, 0.0, 8.0, rng)
        expected = float(depth_sigma(np.array(distance), DEFAULT.depth_noise_m))
        assert float(np.std(noisy - plane)) == pytest.approx(expected, rel=0.05)
    assert float(depth_sigma(np.array(1.0), 0.0019)) == pytest.approx(0.0019)
    biased = noisy_depth(np.full((4, 4), 2.0, dtype=np.float32), 0.0, 0.001, 8.0, rng)
    np.testing.assert_allclose(biased, 2.0 + 0.001 * 4.0, atol=1e-6)  # bias grows with z^2
    empty = np.full((4, 4), 8.0, dtype=np.float32)
    np.testing.assert_array_equal(noisy_depth(empty, 0.01, 0.01, 8.0, rng), empty)


def test_the_robot_software_gets_noisy_depth_and_still_finds_the_marker_within_budget(sim_at_marker):
    sim = sim_at_marker
    drawn = _apply(sim, depth_noise_m=DEFAULT.depth_noise_m, depth_bias_m=DEFAULT.depth_bias_m)
    station = sim.world.station(STATION)
    truth = tf.invert(sim.true_camera_pose()) @ station.T_world_marker()
    for _ in range(3):  # fresh noise in every image
        rgb, depth, intrinsics = sim.render_head_camera()  # what MarkerMotionBehaviour.look gets
        _, exact = render_rgbd(sim.client_id, sim.true_camera_pose(), intrinsics)
        seen = exact < intrinsics.far * 0.999
        residual = (depth - exact - drawn.depth_bias_m * exact**2)[seen]
        normalised = residual / depth_sigma(exact[seen].astype(np.float64), DEFAULT.depth_noise_m)
        assert float(np.std(normalised)) == pytest.approx(1.0, abs=0.05)  # the noise is really there
        observation = detect_marker(rgb, intrinsics, station.marker_id, station.marker_size, depth)
        assert observation is not None and observation.depth_refined
        position_error, angle_error = _pose_difference(observation.T_optical_marker, truth)
        assert position_error <= MAX_MARKER_POSITION_ERROR_M
        assert angle_error <= MAX_MARKER_ANGLE_ERROR_DEG


def test_a_camera_mount_error_is_the_difference_between_the_camera_pose_used_and_the_true_one(sim_at_marker):
    sim = sim_at_marker
    before = _pose_difference(_believed_base_camera(sim), _true_base_camera(sim))
    assert before[0] < 1e-4 and before[1] < 0.01  # model and simulation agree without the error
    drawn = _apply(sim, camera_mount_xyz_m=0.002, camera_mount_rpy_rad=math.radians(0.2))
    error = tf.invert(_believed_base_camera(sim)) @ _true_base_camera(sim)
    np.testing.assert_allclose(error, drawn.T_camera_mount_error(), atol=1e-4)
    offset_mm, turn_deg = _pose_difference(error, np.eye(4))
    assert offset_mm > 0.0005 and turn_deg > 0.05  # a real draw, not zero
    # ... and so the marker the robot locates in base_footprint is off by what the mount error implies
    station = sim.world.station(STATION)
    rgb, depth, intrinsics = sim.render_head_camera()
    observation = detect_marker(rgb, intrinsics, station.marker_id, station.marker_size, depth)
    assert observation is not None
    believed_marker = _believed_base_camera(sim) @ observation.T_optical_marker
    true_marker = tf.invert(sim.robot.base_pose()) @ station.T_world_marker()
    predicted = _believed_base_camera(sim) @ tf.invert(_true_base_camera(sim)) @ true_marker
    assert _pose_difference(believed_marker, predicted)[0] < MAX_MARKER_POSITION_ERROR_M
    assert _pose_difference(believed_marker, true_marker)[0] > 0.001


def test_joint_offsets_shift_the_readings_and_the_poses_fk_gives(sim_at_marker):
    sim = sim_at_marker
    drawn = _apply(sim, joint_offset_rad=DEFAULT.joint_offset_rad)
    assert set(drawn.joint_offsets) == set(disturbances.CALIBRATED_JOINTS)
    assert "torso_lift_joint" not in drawn.joint_offsets
    names = list(sim.robot.joint_index)
    true_positions = {
        name: state[0]
        for name, state in zip(
            names,
            p.getJointStates(
                sim.robot.id, [sim.robot.joint_index[n] for n in names], physicsClientId=sim.client_id
            ),
            strict=True,
        )
    }
    readings = sim.joint_positions()
    for name in names:
        offset = drawn.joint_offsets.get(name, 0.0)
        assert readings[name] - true_positions[name] == pytest.approx(offset, abs=1e-9)
    # a commanded posture is reached in encoder terms; the true joints stand off it by the offsets
    arm = dict(zip(rm.arm_joint_names("right"), (0.3, -0.6, -0.3, 1.6, -1.2, 1.0, 0.4), strict=True))
    assert sim.run(sim.move_joints(arm)).success
    readings = sim.joint_positions()
    for name, target in arm.items():
        assert readings[name] == pytest.approx(target, abs=SETTLE_TOLERANCE)
    frame = "gripper_right_grasping_frame"
    believed = KINEMATICS.forward(readings, frame)
    true_tool = tf.invert(sim.robot.base_pose()) @ sim.robot.link_pose(frame)
    from_true_joints = KINEMATICS.forward(
        {name: value - drawn.joint_offsets.get(name, 0.0) for name, value in readings.items()}, frame
    )
    assert _pose_difference(true_tool, from_true_joints)[0] < 1e-4
    assert _pose_difference(believed, true_tool)[0] > 0.0005  # the robot's belief is off by millimetres


def test_the_calibration_draws_leave_every_earlier_draw_of_a_seed_as_it_was():
    world = load_world()
    with_calibration = disturbances.draw(world, 123, DEFAULT)
    without = disturbances.draw(
        world,
        123,
        dataclasses.replace(
            DEFAULT, camera_mount_xyz_m=0.0, camera_mount_rpy_rad=0.0, joint_offset_rad=0.0, depth_bias_m=0.0
        ),
    )
    for table in ("navigation", "station", "marker", "nest", "plate_mass_factor", "plate_friction_factor"):
        assert getattr(with_calibration, table) == getattr(without, table), table
    assert any(abs(v) > 0 for v in with_calibration.joint_offsets.values())
    assert all(v == 0 for v in without.joint_offsets.values())
    limit = disturbances.CLIP_SIGMAS * DEFAULT.joint_offset_rad
    assert all(abs(v) <= limit for v in with_calibration.joint_offsets.values())


def test_a_bench_height_error_raises_the_true_bench_with_its_marker_and_nests_and_nothing_else():
    """The robot believes the file's height (it takes the nest's height from it); the simulation
    builds the bench, its marker and its nests that much higher. Its draws have a stream of their
    own, so every earlier draw of a seed stays as it was."""
    world = load_world()
    drawn = disturbances.draw(world, 123, DEFAULT)
    without = disturbances.draw(world, 123, dataclasses.replace(DEFAULT, bench_height_m=0.0))
    for table in ("navigation", "station", "marker", "nest", "joint_offsets", "camera_mount", "depth_bias_m"):
        assert getattr(drawn, table) == getattr(without, table), table
    assert set(drawn.bench_height) == {s.name for s in world.stations}
    assert all(
        0 < abs(v) <= disturbances.CLIP_SIGMAS * DEFAULT.bench_height_m for v in drawn.bench_height.values()
    )
    assert all(v == 0 for v in without.bench_height.values())
    raised = disturbances.true_world(world, drawn)
    level = disturbances.true_world(world, without)
    for station in world.stations:
        rise = drawn.bench_height[station.name]
        true, flat = raised.station(station.name), level.station(station.name)
        assert true.table_size[2] == pytest.approx(station.table_size[2] + rise)
        assert true.T_world_marker()[2, 3] - flat.T_world_marker()[2, 3] == pytest.approx(rise)
        assert true.T_world_site(1)[2, 3] - flat.T_world_site(1)[2, 3] == pytest.approx(rise)
        assert np.allclose(true.T_world_site(1)[:2, 3], flat.T_world_site(1)[:2, 3])
    assert "bench_height_mm" in drawn.summary()
