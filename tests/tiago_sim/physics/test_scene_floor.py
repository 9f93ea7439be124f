"""The floor is seen as a grid of small squares (cheaper to render) and must look exactly as the box
it collides as: the same RGB and depth (to float rounding) in the head camera, in the default lab
and a random one."""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest

from tiago_sim import transforms as tf
from tiago_sim.lab.world import load_world
from tiago_sim.lab.world_schema import SCHEMA_FILE
from tiago_sim.layouts.generator import layout_world
from tiago_sim.physics.scene import FLOOR_RGBA, _static_box
from tiago_sim.physics.simulation import Simulation


@pytest.mark.parametrize("lab", ["default", "random layout 75083"])
def test_the_floor_grid_renders_the_pixels_of_the_floor_box(lab: str) -> None:
    world = load_world(SCHEMA_FILE.parent / "default.yaml") if lab == "default" else layout_world(75083)
    sim = Simulation(world, seed=1)
    try:
        client, floor = sim.client_id, sim.scene.floor
        rgb, depth, _ = sim.render_head_camera()
        assert (np.asarray(depth)[-40:] < 0.99 * np.asarray(depth).max()).all()  # the floor is in view
        size = p.getCollisionShapeData(floor, -1, physicsClientId=client)[0][3]
        position, orientation = p.getBasePositionAndOrientation(floor, physicsClientId=client)
        p.resetBasePositionAndOrientation(floor, [0, 0, -500], orientation, physicsClientId=client)
        _static_box(client, size, tf.make_transform(position), FLOOR_RGBA, collide=False)
        box_rgb, box_depth, _ = sim.render_head_camera()
    finally:
        sim.close()
    assert np.array_equal(np.asarray(rgb), np.asarray(box_rgb))
    # depth to float rounding (the triangles interpolate it from other corners): 0.02 mm at 2.6 m
    assert np.allclose(np.asarray(depth), np.asarray(box_depth), rtol=2e-5, atol=0.0)
