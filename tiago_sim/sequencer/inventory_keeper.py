"""The robot side's one inventory: a `LabwareBook` kept on the sequencer's thread, published on
/labware_inventory and written to a file that outlives a restart of the robot side.

Why in the sequencer: every transfer, whichever door it came through (a SiLA server, the Bluesky
device, a plain ROS client), is a goal of this node, and the sensors it settles them on are the
robot's. Readers (the bridge's RobotLink, the Bluesky device) mirror the published records.

Threads: the sequencer's executor thread only (subscription callbacks and task coroutines).
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from labware_interfaces.msg import ErrorCodes, LabwareInventory, LabwareRecord
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from labware_model.holders import GRIPPER, HotelSlot, Location, Nest, location_text
from labware_model.inventory import LabwareBook, NameTaken, SensedPlate, sensed_plates
from labware_model.readings import HotelSlotReading, NestReading
from labware_model.workcell import LabSensors
from tiago_sim.sequencer.plans import TaskRefused

log = logging.getLogger("tiago_sim.sequencer.inventory")

INVENTORY_TOPIC = "/labware_inventory"
REPUBLISH_PERIOD_S = 1.0
INVENTORY_QOS = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


def hotel_readings(robot_state: Any) -> tuple[HotelSlotReading, ...]:
    return tuple(
        HotelSlotReading(HotelSlot(int(s.index)), s.labware_id, s.labware_type, bool(s.occupied))
        for s in robot_state.hotel
    )


def nest_readings(station_states: Any) -> tuple[NestReading, ...]:
    return tuple(
        NestReading(Nest(n.station, int(n.sub_position)), bool(n.occupied), n.labware_id)
        for n in station_states.nests
    )


def sensed_now(
    robot_state: Any,
    station_states: Any,
    sensors: LabSensors | None = None,
    camera_nests: Mapping[Nest, bool] | None = None,
) -> tuple[tuple[SensedPlate, ...], set[Location]]:
    """What the sensors see, and every holder that has a sensor, from one pair of state messages:
    only the sensors the lab has (`sensors`; None: all), the fingers' gap always, and the nests the
    head camera looked into (`camera_nests`) where the nests have none."""
    sensors = sensors or LabSensors()
    hotel = hotel_readings(robot_state) if sensors.hotel else ()
    if sensors.nests and station_states is not None:
        nests = nest_readings(station_states)
    else:
        nests = tuple(NestReading(nest, occupied, "") for nest, occupied in (camera_nests or {}).items())
    held_label = robot_state.held_labware_id if sensors.label_readers else ""
    if not sensors.label_readers:
        hotel = tuple(replace(r, labware_id="") for r in hotel)
        nests = tuple(replace(r, labware_id="") for r in nests)
    plates = sensed_plates(hotel, bool(robot_state.holding), held_label, nests)
    holders: set[Location] = {r.slot for r in hotel} | {r.nest for r in nests} | {GRIPPER}
    return plates, holders


class InventoryKeeper:
    """The book, its topic and its file. `changed()` after every edit publishes and saves."""

    def __init__(self, node: Node, path: Path | None) -> None:
        self.node = node
        self.path = path
        self.book = self._load(path)
        self.followed_sensors = False  # nothing is published before the sensors were read once
        # Grows across restarts too: a reader compares a goal's revision with the latest it has.
        self.revision = time.time_ns() // 1000
        self.publisher = node.create_publisher(LabwareInventory, INVENTORY_TOPIC, INVENTORY_QOS)
        node.create_timer(REPUBLISH_PERIOD_S, self.publish)
        self.publish()

    @staticmethod
    def _load(path: Path | None) -> LabwareBook:
        if path is None or not path.exists():
            return LabwareBook()
        try:
            book = LabwareBook.from_json(path.read_text())
        except (OSError, ValueError) as error:
            log.error("inventory file %s not read (%s): starting from the sensors alone", path, error)
            return LabwareBook()
        log.info("inventory of %d plate(s) read from %s", len(book.records()), path)
        return book

    def changed(self) -> int:
        """A new revision: published at once and saved; returns it."""
        self.revision += 1
        self.publish()
        self._save()
        return self.revision

    def publish(self) -> None:
        """Send the book as it is; not before it has followed the sensors once (a book read from
        the file may name places a restart emptied: readers get the checked one first)."""
        if not self.followed_sensors:
            return
        message = LabwareInventory(revision=self.revision)
        message.stamp = self.node.get_clock().now().to_msg()
        message.records = [
            LabwareRecord(
                labware_id=r.labware_id,
                labware_type=r.labware_type,
                location=location_text(r.location),
                label=r.label,
                note=r.note,
            )
            for r in self.book.records()
        ]
        self.publisher.publish(message)

    def _save(self) -> None:
        if self.path is None:
            return
        temporary = self.path.with_name(self.path.name + ".tmp")
        try:
            temporary.write_text(self.book.to_json())
            os.replace(temporary, self.path)
        except OSError as error:
            log.error("inventory file %s not written: %s", self.path, error)

    def name_for_goal(self, request: Any, source: Location, label: str, label_checks: bool) -> str:
        """Name the goal's plate before anything moves (LabwareBook.name_plate): the goal's id, else
        the name the plate at `source` has, else its label; returns it ("" for an unread plate
        nobody named). A label that reads other than the goal's id is noted, and refused
        (TaskRefused LABEL_MISMATCH) only with `label_checks` on; a name another plate has at
        another place is refused (LABWARE_ELSEWHERE)."""
        name = request.labware_id
        if name and label and name != label and label_checks:
            raise TaskRefused(
                ErrorCodes.LABEL_MISMATCH,
                f"label checks are on: the plate at {source} reads {label!r}, not {name!r}",
            )
        before = self.book.records()
        try:
            record = self.book.name_plate(source, name, request.labware_type, label)
        except NameTaken as taken:
            raise TaskRefused(ErrorCodes.LABWARE_ELSEWHERE, str(taken)) from taken
        if self.book.records() != before:
            self.changed()
        return record.labware_id if record is not None else ""

    def reconcile(self, robot_state: Any, station_states: Any, sensors: LabSensors | None = None) -> None:
        """Follow the sensors the lab has (between transfers only: the caller knows)."""
        plates, holders = sensed_now(robot_state, station_states, sensors)
        if self.book.reconcile(plates, holders) or not self.followed_sensors:
            self.followed_sensors = True
            self.changed()

    def settle(
        self,
        name: str,
        candidates: tuple[Location, ...],
        robot_state: Any,
        stations: Any,
        sensors: LabSensors | None = None,
        *,
        camera_nests: Mapping[Nest, bool] | None = None,
        unsensed_at: Location | None = None,
    ) -> None:
        """After a transfer (LabwareBook.settle), from the latest reports. Where no sensor sees
        the plate, it is at `unsensed_at` if that holder has no sensor: the destination of a
        delivered plate (its checked steps put it there), the source of one no grasp touched."""
        plates, holders = sensed_now(robot_state, stations, sensors, camera_nests)
        unsensed = unsensed_at if unsensed_at not in holders else None
        if name and self.book.settle(name, candidates, plates, unsensed):
            record = self.book.get(name)
            log.info("labware %s is now at %s", name, location_text(record.location) if record else "?")
            self.changed()
