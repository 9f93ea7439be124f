"""The success check of every transfer names each limit a plate in its nest missed.

Why: a campaign failure read "1.8 mm from the centre ... outside the nest's tolerance" while the
per-axis limit is 2.5 mm, so the plate must have been raised or tilted, and nobody could tell
which. The plate is put in a pose here directly: this tests the judge, not the robot.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet as p
import pytest

from labware_model.holders import Nest
from tiago_sim import transforms as tf
from tiago_sim.lab.world import load_world
from tiago_sim.physics.simulation import Simulation

PLATE, NEST = "plate_001", Nest("station_a", 1)


@pytest.fixture(scope="module")
def sim() -> Simulation:
    simulation = Simulation(load_world(), seed=3)
    yield simulation
    simulation.close()


def _put_plate(sim: Simulation, T_site_plate_bottom: np.ndarray) -> None:
    """Place the plate so its bottom centre sits at that pose in the nest frame (no physics step)."""
    height = sim.scene.plate_types[PLATE].height
    T_world_bottom = sim.world.station(NEST.station).T_world_site(NEST.sub_position) @ T_site_plate_bottom
    T_world_plate = T_world_bottom @ tf.make_transform((0.0, 0.0, height / 2))
    position, quaternion = tf.to_pose(T_world_plate)
    p.resetBasePositionAndOrientation(
        sim.scene.plates[PLATE], position.tolist(), quaternion.tolist(), physicsClientId=sim.client_id
    )


@pytest.mark.parametrize(
    ("T_site_plate_bottom", "in_nest", "named"),
    [
        (np.eye(4), True, ""),
        (tf.make_transform((0.0, 0.0, 0.003)), False, "raised 3.0 mm (limit 2.0)"),
        (tf.from_xyz_rpy((0, 0, 0), (math.radians(1.5), 0, 0)), False, "tilted 1.5 deg (limit 1.0)"),
        (tf.make_transform((0.0, 0.0035, 0.0)), False, "off across the nest by 3.5 mm (limit 2.5)"),
        (tf.from_planar(0.0, 0.0, math.radians(3.0)), False, "turned 3.0 deg (limit 2.0)"),
    ],
)
def test_every_missed_limit_is_named(
    sim: Simulation, T_site_plate_bottom: np.ndarray, in_nest: bool, named: str
) -> None:
    _put_plate(sim, T_site_plate_bottom)
    check = sim.check_placement(PLATE, NEST)
    assert check.location == NEST
    assert check.in_nest is in_nest
    assert check.outside == named
