"""Walls at the floor's edge, built into a test's Simulation as the occupancy map draws them.

Why in tests only: the scene gets its own edge walls from the navigation work on another branch;
until that lands here, localisation tests stand the same walls up themselves, so the laser sees
the lab's outline the map has (benches alone leave long stretches of a drive with one face in view).
"""

from __future__ import annotations

import pybullet as p

from tiago_sim.navigation.occupancy_map import WALL_THICKNESS
from tiago_sim.physics.simulation import Simulation

WALL_HEIGHT = 1.0


def add_edge_walls(sim: Simulation) -> list[int]:
    """Four static boxes, WALL_THICKNESS thick, just inside the floor's edge; their body ids."""
    half = sim.world.floor_size / 2
    inner = half - WALL_THICKNESS / 2
    client = sim.client_id
    bodies = []
    for x, y, size_x, size_y in (
        (0.0, inner, 2 * half, WALL_THICKNESS),
        (0.0, -inner, 2 * half, WALL_THICKNESS),
        (inner, 0.0, WALL_THICKNESS, 2 * half),
        (-inner, 0.0, WALL_THICKNESS, 2 * half),
    ):
        shape = p.createCollisionShape(
            p.GEOM_BOX, halfExtents=[size_x / 2, size_y / 2, WALL_HEIGHT / 2], physicsClientId=client
        )
        bodies.append(p.createMultiBody(0.0, shape, -1, [x, y, WALL_HEIGHT / 2], physicsClientId=client))
    return bodies
