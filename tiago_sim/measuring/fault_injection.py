"""Test and fault injection for the sim node: hide a marker, take a plate away, drop one mid-drive,
knock one out of a nest the robot just released it into.

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

from lab_description.world import World
from labware_model.holders import Nest
from tiago_description.transforms import make_transform, to_pose

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


PARKING_MARGIN_M = 0.5  # removed plates lie on the floor this far inside its corner, away from every path
DROP_SIDEWAYS_M = 0.45  # beside the tray: clear of the base (r 0.27 m) plus half a plate diagonal
DROP_HEIGHT_M = 0.02  # just above the tray, so the plate falls from hotel height
DROP_PUSH_M_S = 0.5  # outward push the slipping plate gets
DRIVING_SPEED_M_S = 0.2  # the base counts as driving (not turning on the spot) above this speed


class PlateFaults:
    """Physical plate faults: a plate taken away from its place, lost from the hotel mid-drive, or
    knocked out of a nest right after a release.

    ``remove(sim, plate)`` moves the plate onto the floor far from every station (as if someone
    took it, out of the gripper too); ``arm_drop(plate)`` makes the plate slip out of the hotel the
    next time the base drives, and physics drops it on the floor beside the robot;
    ``arm_knock(plate)`` takes the plate away (as `remove`) the moment a gripper that held it starts
    to let go of it in a nest; ``restore(sim)`` puts every plate moved or dropped this way back where the
    world file puts it (if that place is free), so a test can go on. Nothing here tells the robot
    software: it must find out from its sensors. Uses the simulation's own (true) world.
    Runs on: the sim thread.
    """

    def __init__(self) -> None:
        self.drop_armed = ""
        self.knock_armed = ""
        self.knock_seen_held = False
        self.faulted: set[str] = set()

    def remove(self, sim: Any, labware_id: str) -> None:
        body = self._body(sim, labware_id)
        for gripper in sim.grippers.values():
            if gripper.attached_id == labware_id:
                gripper.detach()  # a hand pulling the plate out breaks the grip
        corner = sim.world.floor_size / 2 - PARKING_MARGIN_M
        labware = sim.scene.plate_types[labware_id]
        _teleport(sim, body, [corner, corner, labware.height / 2 + 0.001], [0, 0, 0, 1])
        self.faulted.add(labware_id)
        log.info("plate %s taken to the floor at (%.1f, %.1f) (fault injection)", labware_id, corner, corner)

    def arm_drop(self, sim: Any, labware_id: str) -> None:
        self._body(sim, labware_id)
        self.drop_armed = labware_id
        log.info("plate %s will slip out of the hotel during the next drive (fault injection)", labware_id)

    def drop_if_driving(self, sim: Any) -> bool:
        """Called on the sim thread after every batch of steps while a drop is armed: push the plate
        off the tray once the base drives with it aboard; True when done (dropped, or disarmed)."""
        labware_id = self.drop_armed
        if not labware_id:
            return True
        if abs(sim.base.v) < DRIVING_SPEED_M_S:
            return False
        slot = next((r.slot.index for r in sim.hotel_readings() if r.labware_id == labware_id), 0)
        if not slot:
            return False
        T_world_slot = sim.robot.link_pose(f"hotel_slot_{slot}")
        side = 1.0 if slot % 2 else -1.0
        labware = sim.scene.plate_types[labware_id]
        T_world_start = T_world_slot @ make_transform(
            (0.0, side * DROP_SIDEWAYS_M, DROP_HEIGHT_M + labware.height / 2)
        )
        position, quat = to_pose(T_world_start)
        outward = T_world_slot[:3, 1] * side * DROP_PUSH_M_S
        _teleport(sim, sim.scene.plates[labware_id], position.tolist(), quat.tolist(), outward.tolist())
        self.drop_armed = ""
        self.faulted.add(labware_id)
        log.info("plate %s slipped out of hotel slot %d mid-drive (fault injection)", labware_id, slot)
        return True

    def arm_knock(self, sim: Any, labware_id: str) -> None:
        self._body(sim, labware_id)
        self.knock_armed, self.knock_seen_held = labware_id, False
        log.info("plate %s will be knocked out of the nest it is released in (fault injection)", labware_id)

    def knock_if_released(self, sim: Any) -> bool:
        """Called on the sim thread after every batch of steps while a knock is armed: once a gripper
        held the plate and let go of it (the release starts by dropping the travel attach, before the
        fingers open) in a nest, take it away; True when done."""
        labware_id = self.knock_armed
        if not labware_id:
            return True
        if any(gripper.attached_id == labware_id for gripper in sim.grippers.values()):
            self.knock_seen_held = True
            return False
        in_nest = any(reading.labware_id == labware_id for reading in sim.nest_readings())
        if not (self.knock_seen_held and in_nest):
            return False
        self.knock_armed = ""
        log.info("plate %s knocked out of its nest after the release (fault injection)", labware_id)
        self.remove(sim, labware_id)
        return True

    def restore(self, sim: Any) -> None:
        """Put faulted plates back at their world-file nests (skipped where a plate already sits)."""
        self.drop_armed = self.knock_armed = ""
        for plate, holder in sim.world.plates.items():
            if plate.labware_id not in self.faulted or not isinstance(holder, Nest):
                continue
            T_world_site = sim.world.station(holder.station).T_world_site(holder.sub_position)
            if any(reading.nest == holder and reading.occupied for reading in sim.nest_readings()):
                log.warning("not restoring %s: its nest is taken", plate.labware_id)
                continue
            labware = sim.scene.plate_types[plate.labware_id]
            centre = make_transform((0.0, 0.0, labware.height / 2 + 0.0005))
            position, quat = to_pose(T_world_site @ centre)
            _teleport(sim, sim.scene.plates[plate.labware_id], position.tolist(), quat.tolist())
            self.faulted.discard(plate.labware_id)
            log.info("plate %s restored to %s", plate.labware_id, holder)

    @staticmethod
    def _body(sim: Any, labware_id: str) -> int:
        if labware_id not in sim.scene.plates:
            raise ValueError(f"unknown plate {labware_id!r}")
        return sim.scene.plates[labware_id]


def _teleport(sim: Any, body: int, position: list, quat: list, velocity: list | None = None) -> None:
    """Move a body and give it a velocity (zero unless given); physics takes over from there."""
    for labware_id, plate in sim.scene.plates.items():
        if plate == body:
            sim.hotel_clamp.open(labware_id)  # a clamped plate would spring back to the tray
    p.resetBasePositionAndOrientation(body, position, quat, physicsClientId=sim.client_id)
    p.resetBaseVelocity(body, velocity or [0, 0, 0], [0, 0, 0], physicsClientId=sim.client_id)
