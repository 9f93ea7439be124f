"""Test and fault injection for the sim node: hide a station's marker from the head camera.

Why: a test of MARKER_NOT_FOUND needs a real occlusion in the rendered image, not a flag in
the perception code. The occluder is a visual-only panel (no collision shape, so it cannot push
anything) standing in front of the marker, placed from the world description. It exists only
while the sim node's parameter ``fault.occlude_marker`` names the station.
Runs on: the sim thread (it creates PyBullet bodies).
"""

from __future__ import annotations

import logging
from typing import Any

import pybullet as p

from tiago_sim.transforms import make_transform, to_pose
from tiago_sim.world import World

log = logging.getLogger(__name__)

PANEL_SIZE_M = (0.30, 0.30, 0.01)  # wide enough to cover marker and quiet zone at any POI view
PANEL_DISTANCE_M = 0.06  # in front of the marker face, between marker and nest


class Occluders:
    """At most one occluding panel, in front of the marker of the station named last."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.body = -1
        self.station = ""

    def set_occluded(self, sim: Any, station_name: str) -> None:
        client = sim.client_id
        if self.body >= 0:
            p.removeBody(self.body, physicsClientId=client)
            self.body, self.station = -1, ""
        if not station_name:
            log.info("marker occlusion removed")
            return
        station = self.world.station(station_name)
        T_world_panel = station.T_world_marker() @ make_transform((0.0, 0.0, PANEL_DISTANCE_M))
        position, quat = to_pose(T_world_panel)
        visual = p.createVisualShape(
            p.GEOM_BOX,
            halfExtents=[s / 2 for s in PANEL_SIZE_M],
            rgbaColor=[0.3, 0.3, 0.35, 1],
            physicsClientId=client,
        )
        self.body = p.createMultiBody(
            0.0, -1, visual, position.tolist(), quat.tolist(), physicsClientId=client
        )
        self.station = station_name
        log.info("marker of %s occluded (fault injection)", station_name)
