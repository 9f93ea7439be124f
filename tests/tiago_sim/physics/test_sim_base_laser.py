"""The base laser in physics: ranges to a wall of known place, its noise, its seed, never the robot."""

from __future__ import annotations

import math

import numpy as np
import pybullet as p

from lab_description.world import load_world
from tiago_sim.physics.simulation import Simulation


def _wall_ahead(sim: Simulation, distance: float) -> float:
    """A 4 m wide wall square to the base's heading, ``distance`` ahead of the laser; its face's x."""
    x, y, yaw = sim.robot.base_xy_yaw()
    assert abs(yaw) < 1e-3  # the default lab's robot starts docked facing +x
    face_x = x + sim.laser.spec.mount_x + distance
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.05, 2.0, 0.5], physicsClientId=sim.client_id)
    p.createMultiBody(0.0, shape, -1, [face_x + 0.05, y, 0.5], physicsClientId=sim.client_id)
    return face_x


def test_laser_measures_a_wall_where_it_stands_with_the_documented_noise_and_never_sees_the_robot():
    sim = Simulation(load_world(), seed=11)
    try:
        spec = sim.laser.spec
        assert spec.beams == 661 and math.isclose(spec.angles()[-1], math.radians(110.0), abs_tol=1e-9)
        _wall_ahead(sim, 1.5)
        angles = spec.angles()
        facing = np.abs(angles) < math.radians(40.0)  # these beams all meet the wall's face
        expected = 1.5 / np.cos(angles[facing])
        scans = np.array([sim.laser.scan()[facing] for _ in range(20)])
        errors = scans - expected
        assert abs(np.mean(errors)) < 0.002
        assert 0.017 < np.std(errors) < 0.023  # 2 cm, 1 sigma
        assert np.all(np.abs(np.round(scans, 3) - scans) < 1e-9)  # whole millimetres
        truth = sim.laser.true_ranges()
        np.testing.assert_allclose(truth[facing], expected, atol=1e-3)
        # beams sideways pass the robot's own base, wheels and arms: what they see is not the robot
        assert np.isfinite(truth).all()  # the floor's edge walls close the lab within 10 m
        assert truth.min() > 0.3
    finally:
        sim.close()


def test_laser_noise_comes_from_the_seed_and_does_not_disturb_odometry():
    scans, odometry = [], []
    for scanning in (True, False):
        sim = Simulation(load_world(), seed=4, odometry_noise=0.01)
        try:
            if scanning:
                scans = [sim.laser.scan() for _ in range(2)]
            assert sim.run(sim.undock()).success
            odometry.append(sim.odometry())
        finally:
            sim.close()
    assert odometry[0] == odometry[1]  # the laser draws from its own stream
    seen = np.isfinite(scans[0])
    assert seen.sum() > 50 and not np.array_equal(scans[0][seen], scans[1][seen])
    again = Simulation(load_world(), seed=4)
    try:
        np.testing.assert_array_equal(again.laser.scan(), scans[0])
    finally:
        again.close()
