"""The laser's numpy cast against the lab's cut by its plane agrees with PyBullet's ray test, and
hands over to the ray test where the cut would not be exact.

Real parts: PyBullet worlds built from the default lab and generated layouts, rayTestBatch as the
reference.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet as p
import pytest

from lab_description.world import load_world
from tiago_sim.layouts.generator import layout_world
from tiago_sim.physics import plane_caster
from tiago_sim.physics.robot_body import ROBOT_COLLISION_GROUP
from tiago_sim.physics.simulation import Simulation

POSES_PER_LAB = 25


def _bullet_ranges(sim: Simulation, origin: np.ndarray, directions: np.ndarray) -> np.ndarray:
    laser = sim.laser
    start, stop, height = laser._start_distance, laser.spec.range_max, laser.spec.mount_z
    column = np.full((len(directions), 1), height)
    hits = p.rayTestBatch(
        np.hstack([origin + directions * start[:, None], column]),
        np.hstack([origin + directions * stop, column]),
        collisionFilterMask=~ROBOT_COLLISION_GROUP,
        physicsClientId=sim.client_id,
    )
    found = np.array([(hit[0], hit[2]) for hit in hits], dtype=float)
    return np.where(found[:, 0] >= 0, start + found[:, 1] * (stop - start), np.inf)


@pytest.mark.parametrize("seed", [None, 40004, 40011])
def test_the_numpy_cast_matches_bullets_ray_test_but_for_beams_grazing_a_corner(seed: int | None) -> None:
    world = load_world() if seed is None else layout_world(seed)
    sim = Simulation(world, seed=1)
    try:
        laser, rng = sim.laser, np.random.default_rng(seed or 0)
        sections = plane_caster.cross_sections(sim.client_id, laser.spec.mount_z, {sim.robot.id})
        assert sections is not None and len(sections.rectangles) >= 4 + len(world.stations)
        half, compared, off = world.floor_size / 2, 0, 0
        while compared < POSES_PER_LAB:
            origin = rng.uniform(-half, half, size=2)
            yaw = rng.uniform(-math.pi, math.pi)
            c, s = math.cos(yaw), math.sin(yaw)
            directions = laser._directions @ np.array([[c, -s], [s, c]]).T
            everywhere = np.zeros(len(directions))
            if np.isfinite(plane_caster.cast(sections, origin, directions, everywhere, 0.6)).any():
                continue  # too close to something: a robot could not stand here
            start, stop = laser._start_distance, laser.spec.range_max
            ours = plane_caster.cast(sections, origin, directions, start, stop)
            theirs = _bullet_ranges(sim, origin, directions)
            both = np.isfinite(ours) & np.isfinite(theirs)
            agree = np.isfinite(ours) == np.isfinite(theirs)
            agree[both] = np.abs(ours[both] - theirs[both]) < 1e-3
            off += int((~agree).sum())
            compared += 1
        assert off <= 0.002 * POSES_PER_LAB * len(laser._directions), f"{off} beams disagree"
    finally:
        sim.close()


def _straight_ahead_with(shape: str) -> tuple[plane_caster.CrossSections | None, float]:
    """The default lab with one static body whose near side is 1 m straight ahead of the laser:
    the plane's cut through the lab, and the noise-free range of the beam straight ahead."""
    sim = Simulation(load_world(), seed=3)
    try:
        laser, client = sim.laser, sim.client_id
        x, y, _ = sim.robot.base_xy_yaw()
        face, height = x + laser.spec.mount_x + 1.0, laser.spec.mount_z
        if shape == "tilted box":  # rolled about the beam: the face it shows the beam stays square
            body = p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.05, 0.5, 0.3], physicsClientId=client)
            pose = ([face + 0.05, y, height], p.getQuaternionFromEuler([0.3, 0.0, 0.0]))
        else:
            body = p.createCollisionShape(p.GEOM_CYLINDER, radius=0.2, height=1.0, physicsClientId=client)
            pose = ([face + 0.2, y, 0.5], [0.0, 0.0, 0.0, 1.0])
        p.createMultiBody(0.0, body, -1, *pose, physicsClientId=client)
        sections = plane_caster.cross_sections(client, height, {sim.robot.id})
        return sections, float(laser.true_ranges()[len(laser._directions) // 2])
    finally:
        sim.close()


def test_a_tilted_box_in_the_plane_sends_the_scan_to_bullets_ray_test() -> None:
    sections, ahead = _straight_ahead_with("tilted box")
    assert sections is None
    assert ahead == pytest.approx(1.0, abs=2e-3)


def test_an_upright_cylinder_is_cut_as_a_circle() -> None:
    sections, ahead = _straight_ahead_with("cylinder")
    assert sections is not None and len(sections.circles) == 1
    assert ahead == pytest.approx(1.0, abs=1e-6)
