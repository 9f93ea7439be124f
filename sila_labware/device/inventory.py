"""Where each plate is, keyed by LabwareUniqueID, kept true after every success and failure.

The inventory never guesses from what a command intended: after each transfer (successful or
not) the SiLA layer calls `settle()` with what the robot side reports (the robot's hotel and
gripper from /robot_state, the stations' nest sensors from /station_states), and the plate is
put where those observations say, or marked unknown.

Thread-safe (one lock); change listeners run on the thread that made the change.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from labware_model.holders import GRIPPER, UNKNOWN, HotelSlot, Location, Nest, location_text
from labware_model.readings import NestReading
from ros_bridge.workcell import RobotStatus

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class LabwareRecord:
    """A plate the robot handled and where it is: a nest, a hotel slot, the gripper, or `UNKNOWN`."""

    labware_id: str
    labware_type: str
    location: Location


def unread_in_slot(robot_status: RobotStatus, slot: HotelSlot | None) -> bool:
    """The hotel slot's presence sensor sees a plate whose label its reader could not read."""
    return slot is not None and any(r.slot == slot and r.unread for r in robot_status.hotel)


def observed_location(
    labware_id: str,
    handover: Nest | None,
    robot_status: RobotStatus,
    nests: Iterable[NestReading],
    slot: HotelSlot | None = None,
) -> Location:
    """Where the observations put a plate: robot hotel, gripper, a nest reporting it; else, where
    a sensor sees a plate without reading its label, the transfer's own holders: its hotel slot, the
    gripper (it carries one plate at most), its hand-over nest; otherwise unknown."""
    for reading in robot_status.hotel:
        if reading.labware_id == labware_id:
            return reading.slot
    if robot_status.held_labware_id == labware_id:
        return GRIPPER
    nests = tuple(nests)
    for reading in nests:
        if reading.occupied and reading.labware_id == labware_id:
            return reading.nest
    if slot is not None and unread_in_slot(robot_status, slot):
        return slot
    if (
        (slot is not None or handover is not None)
        and robot_status.holding
        and not robot_status.held_labware_id
    ):
        return GRIPPER
    if handover is not None:
        for reading in nests:
            if reading.nest == handover and reading.occupied and not reading.labware_id:
                return handover
    return UNKNOWN


class Inventory:
    """LabwareUniqueID -> type and location."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._records: dict[str, LabwareRecord] = {}
        self._listeners: list[Callable[[tuple[LabwareRecord, ...]], None]] = []

    def add_listener(self, listener: Callable[[tuple[LabwareRecord, ...]], None]) -> None:
        with self._lock:
            self._listeners.append(listener)

    def locate(self, labware_id: str) -> LabwareRecord | None:
        with self._lock:
            return self._records.get(labware_id)

    def records(self) -> tuple[LabwareRecord, ...]:
        with self._lock:
            return tuple(self._records[key] for key in sorted(self._records))

    def in_hotel_slot(self, slot: int) -> LabwareRecord | None:
        """The plate recorded in hotel slot `slot` (1-based), if any."""
        with self._lock:
            return next(
                (
                    record
                    for record in self._records.values()
                    if isinstance(record.location, HotelSlot) and record.location.index == slot
                ),
                None,
            )

    def record(self, labware_id: str, labware_type: str, location: Location) -> None:
        """Put a plate somewhere; keeps a known type when `labware_type` is empty."""
        with self._lock:
            previous = self._records.get(labware_id)
            kept_type = labware_type or (previous.labware_type if previous else "")
            new_record = LabwareRecord(labware_id, kept_type, location)
            if previous == new_record:
                return
            self._records[labware_id] = new_record
            snapshot = tuple(self._records[key] for key in sorted(self._records))
            listeners = list(self._listeners)
        logger.info("labware %s is now at %s", labware_id, location_text(location))
        for listener in listeners:
            listener(snapshot)

    def settle(
        self,
        labware_id: str,
        labware_type: str,
        handover: Nest | None,
        robot_status: RobotStatus,
        nests: Iterable[NestReading],
        slot: HotelSlot | None = None,
    ) -> Location:
        """Record where the observations put the plate (after a transfer, whatever its outcome; `slot`:
        the transfer's hotel slot)."""
        location = observed_location(labware_id, handover, robot_status, nests, slot)
        self.record(labware_id, labware_type, location)
        return location

    def observe_robot(self, robot_status: RobotStatus) -> None:
        """Take in plates the robot reports aboard (hotel slots, gripper) under their ids."""
        for reading in robot_status.hotel:
            if reading.labware_id:
                self.record(reading.labware_id, reading.labware_type, reading.slot)
        if robot_status.held_labware_id:
            self.record(robot_status.held_labware_id, "", GRIPPER)
