"""Base drive in physics: reaches POIs on odometry within the TIAGo limits; dock and undock by contact."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lab_description.world import load_world
from tests.helpers.sim_steps import step_for
from tiago_description import robot_model as rm
from tiago_description import transforms as tf
from tiago_sim.physics.simulation import Simulation


def _drive_recording(sim: Simulation, motion) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step to the end, recording sim time, the physical forward speed and yaw rate of the base."""
    times, speeds, rates = [], [], []
    while not motion.done:
        sim.step()
        v, w = sim.robot.base_twist()
        times.append(sim.sim_time)
        speeds.append(v)
        rates.append(w)
        assert sim.sim_time < 120.0
    return np.array(times), np.array(speeds), np.array(rates)


@pytest.mark.parametrize("noise", [0.0, 0.0005])
def test_base_drives_to_a_station_poi_within_tolerance_and_limits(noise):
    world = load_world()
    sim = Simulation(world, seed=7, odometry_noise=noise)
    try:
        assert sim.is_docked()
        undock = sim.run(sim.undock())
        assert undock.success and not sim.is_docked()
        goal = world.pois["station_a_work"]
        motion = sim.drive_to(goal.x, goal.y, goal.yaw)
        times, speeds, rates = _drive_recording(sim, motion)
        assert motion.success, motion.message
        x, y, yaw = sim.odometry()
        assert math.hypot(x - goal.x, y - goal.y) < 0.015
        assert abs(tf.wrap_angle(yaw - goal.yaw)) < 0.01
        truth = sim.robot.base_pose()
        drift = math.hypot(truth[0, 3] - x, truth[1, 3] - y)
        assert drift < (0.005 if noise == 0.0 else 0.10)
        if noise == 0.0:
            assert abs(tf.wrap_angle(tf.yaw_of(truth) - goal.yaw)) < 0.01
        # TIAGo limits, measured on the physical base (5-step averages against solver jitter)
        assert np.max(np.abs(speeds)) <= rm.MAX_LINEAR_SPEED + 0.01
        assert np.max(np.abs(rates)) <= rm.MAX_ANGULAR_SPEED + 0.01
        window = np.ones(5) / 5  # steps may differ in length (free motion): divide by their own times
        accel = np.abs(np.diff(np.convolve(speeds, window, mode="valid"))) / np.diff(
            np.convolve(times, window, mode="valid")
        )
        assert np.max(accel) <= rm.MAX_LINEAR_ACCEL * 1.1
        assert np.max(np.abs(speeds)) > 0.5 * rm.MAX_LINEAR_SPEED  # it did cruise
    finally:
        sim.close()


def test_drive_is_refused_while_docked_and_dock_closes_the_contact():
    world = load_world()
    sim = Simulation(world, seed=3)
    try:
        refused = sim.drive_to(0.0, 0.0, 0.0)
        assert refused.done and not refused.success and refused.error_code == "DOCKED"
        assert sim.run(sim.undock()).success
        lab = world.pois["lab_centre"]
        assert sim.run(sim.drive_to(lab.x, lab.y, lab.yaw)).success
        assert not sim.is_docked()
        dock = sim.run(sim.dock())
        assert dock.success, dock.message
        assert sim.is_docked()
        truth = sim.robot.base_pose()
        assert math.hypot(truth[0, 3] - world.dock_pose.x, truth[1, 3] - world.dock_pose.y) < 0.05
    finally:
        sim.close()


def test_cancel_stops_the_base_and_reports_canceled():
    world = load_world()
    sim = Simulation(world, seed=1)
    try:
        sim.run(sim.undock())
        motion = sim.drive_to(3.0, -1.0, 0.0)
        step_for(sim, 2.0)  # mid-drive
        assert not motion.done
        motion.cancel()
        sim.run(motion)
        assert motion.done and not motion.success and motion.error_code == "CANCELED"
        assert sim.robot.base_twist()[0] == pytest.approx(0.0, abs=0.01)
        assert not sim.busy()
    finally:
        sim.close()
