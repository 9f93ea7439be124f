"""The plate sensors of the lab and the robot, and the physics' own judgement of a delivery.

Why together: both read where plates rest from PyBullet. The presence sensors (one per nest, one
per hotel pocket) report what a real sensor could: a plate there; which one only as far as the
holder's identity reader read its label (identity_readers, which can fail). ``check_placement`` is
ground truth and serves success checks only, never robot control; whether a plate is seated, and
every limit, comes from `seating`. Lives on the sim thread.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pybullet as p

from lab_description.world import World
from labware_model.holders import FLOOR, GRIPPER, UNKNOWN, HotelSlot, Location, Nest, location_text
from labware_model.readings import HotelSlotReading, NestReading, PlacementCheck
from tiago_description import transforms as tf
from tiago_sim.physics.identity_readers import IdentityReaders
from tiago_sim.physics.robot_body import RobotBody
from tiago_sim.physics.scene import plate_bottom_pose
from tiago_sim.physics.seating import PoseInNest, SeatingLimits

NEST_SENSOR_RANGE = 0.02  # m: presence sensor sees a plate whose centre is this close to the site
# m: and whose bottom is at most this far above the pocket floor. A nest's sensor is a short-range
# proximity sensor in the pocket floor: a plate resting on a lead-in's rim (3 mm up at its centre,
# a failure mode campaigns have shown) is not seen, so the robot reports it as not
# placed instead of delivered. A seated plate lies within the success check's 1 mm.
NEST_SENSOR_GAP = 0.0015
HOTEL_SENSOR_GAP = 0.01  # m: the hotel pockets' sensors see a plate anywhere on their ramps; and
# where a plate is, as ground truth: one resting on a nest's rim is at that nest, not seated in it


class PlateSensing:
    """Presence sensors and the placement check over one scene (see the module docstring)."""

    def __init__(
        self, client_id: int, world: World, robot: RobotBody, scene: Any, grippers: dict[str, Any]
    ) -> None:
        self._client_id = client_id
        self._world = world
        self._robot = robot
        self._scene = scene
        self._grippers = grippers
        self._nest_sites_cache: list[tuple[Nest, np.ndarray]] | None = None
        self.readers = IdentityReaders()  # perfect readers unless a disturbance sets a failure rate

    def plate_bottom(self, labware_id: str) -> np.ndarray:
        body = self._scene.plates[labware_id]
        return plate_bottom_pose(self._client_id, body, self._scene.plate_types[labware_id])

    def _site_offset(self, T_world_site: np.ndarray, labware_id: str) -> np.ndarray:
        return tf.invert(T_world_site) @ self.plate_bottom(labware_id)

    def _plate_bottom_points(self) -> list[tuple[str, np.ndarray]]:
        """World position of every plate's bottom centre (one query per plate, shared by all sensors)."""
        points = []
        for labware_id, body in self._scene.plates.items():
            position, quat = p.getBasePositionAndOrientation(body, physicsClientId=self._client_id)
            up = np.array(p.getMatrixFromQuaternion(quat)[2::3])  # the plate's z axis
            half_height = self._scene.plate_types[labware_id].height / 2
            points.append((labware_id, np.asarray(position) - half_height * up))
        return points

    @staticmethod
    def _plate_near(T_world_site: np.ndarray, bottoms: list[tuple[str, np.ndarray]], max_gap: float) -> str:
        """The plate whose bottom centre the presence sensor of this site sees, or ""."""
        for labware_id, point in bottoms:
            offset = T_world_site[:3, :3].T @ (point - T_world_site[:3, 3])
            if math.hypot(offset[0], offset[1]) < NEST_SENSOR_RANGE and -0.01 < offset[2] < max_gap:
                return labware_id
        return ""

    def _nest_sites(self) -> list[tuple[Nest, np.ndarray]]:
        """(nest, T_world_site) of every nest; the stations never move, so computed once."""
        if self._nest_sites_cache is None:
            self._nest_sites_cache = [
                (nest, station.T_world_site(nest.sub_position))
                for station in self._world.stations
                for nest in station.nests()
            ]
        return self._nest_sites_cache

    def _nest_occupants(self, max_gap: float = NEST_SENSOR_GAP) -> list[tuple[Nest, str]]:
        """(nest, the plate in it or "") for every nest: what the sensors see, or with a wider
        `max_gap` the ground truth of where a plate is (a plate on a rim is at that nest)."""
        bottoms = self._plate_bottom_points()
        sites = self._nest_sites()
        return [(nest, self._plate_near(T_world_site, bottoms, max_gap)) for nest, T_world_site in sites]

    def _hotel_occupants(self) -> list[tuple[HotelSlot, str]]:
        """(slot, the plate physically in it or "") for every hotel pocket: ground truth."""
        bottoms = self._plate_bottom_points()
        return [
            (
                HotelSlot(index),
                self._plate_near(self._robot.link_pose(f"hotel_slot_{index}"), bottoms, HOTEL_SENSOR_GAP),
            )
            for index in range(1, self._world.hotel_slots + 1)
        ]

    def nest_readings(self) -> list[NestReading]:
        """Presence from physics; the id as the nest's reader read it."""
        return [
            NestReading(nest, bool(labware_id), self.readers.report(location_text(nest), labware_id))
            for nest, labware_id in self._nest_occupants()
        ]

    def hotel_readings(self) -> list[HotelSlotReading]:
        """The id (and the type it names) as the pocket's reader read it ("" when empty or unread), and
        whether a plate is there at all (the pocket's presence switch)."""
        result = []
        for slot, present in self._hotel_occupants():
            labware_id = self.readers.report(location_text(slot), present)
            labware_type = self._scene.plate_types[labware_id].name if labware_id else ""
            result.append(HotelSlotReading(slot, labware_id, labware_type, occupied=bool(present)))
        return result

    def held_reading(self, side: str, present: str) -> str:
        """The id the gripper's reader gives for the plate between its pads ("" if none or unread)."""
        return self.readers.report(f"gripper_{side}", present)

    def check_placement(self, labware_id: str, nest: Nest | None) -> PlacementCheck:
        if labware_id not in self._scene.plates:
            return PlacementCheck(False, False, math.inf, math.inf, UNKNOWN)
        location = self._locate(labware_id)
        if nest is None:
            return PlacementCheck(True, False, math.nan, math.nan, location)
        site = self._world.station(nest.station)
        labware = self._scene.plate_types[labware_id]
        pose = PoseInNest.of(self._site_offset(site.T_world_site(nest.sub_position), labware_id), labware)
        missed = SeatingLimits.for_nest(labware, site.nest_clearance).missed(pose)
        position_error = math.hypot(pose.x, pose.y)
        return PlacementCheck(True, not missed, position_error, abs(pose.yaw), location, ", ".join(missed))

    def _locate(self, labware_id: str) -> Location:
        for _side, gripper in self._grippers.items():
            if gripper.attached_id == labware_id or gripper.touching() == labware_id:
                return GRIPPER
        for nest, present in self._nest_occupants(HOTEL_SENSOR_GAP):
            if present == labware_id:
                return nest
        for slot, present in self._hotel_occupants():
            if present == labware_id:
                return slot
        if self.plate_bottom(labware_id)[2, 3] < 0.05:
            return FLOOR
        return UNKNOWN
