"""Where each plate is, keyed by LabwareUniqueID, kept true after every success and failure.

The inventory never guesses from what a command intended: after each transfer (successful or
not) the SiLA layer calls `settle()` with what the robot side reports (the robot's hotel and
gripper from /robot_state, the stations' nest sensors from /station_states), and the plate is
put where those observations say, or marked unknown.

Thread-safe (one lock); change listeners run on the thread that made the change.
"""

from __future__ import annotations

import enum
import logging
import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from ros_bridge.workcell import NestOccupancy, RobotStatus
from sila_labware.device.validation import Handover

logger = logging.getLogger(__name__)


class LocationKind(enum.Enum):
    STATION = "station"
    HOTEL = "hotel"
    GRIPPER = "gripper"
    UNKNOWN = "unknown"


@dataclass(frozen=True)
class LabwareLocation:
    """A station nest (station, index = sub-position), a hotel slot (index), the gripper, or unknown."""

    kind: LocationKind
    station: str = ""
    index: int = 0

    @property
    def aboard(self) -> bool:
        return self.kind in (LocationKind.HOTEL, LocationKind.GRIPPER)

    def __str__(self) -> str:
        if self.kind is LocationKind.STATION:
            return f"station:{self.station}:{self.index}"
        if self.kind is LocationKind.HOTEL:
            return f"hotel:{self.index}"
        return self.kind.value


UNKNOWN = LabwareLocation(LocationKind.UNKNOWN)
GRIPPER = LabwareLocation(LocationKind.GRIPPER)


def at_station(handover: Handover) -> LabwareLocation:
    return LabwareLocation(LocationKind.STATION, handover.station, handover.sub_position)


def in_hotel(slot: int) -> LabwareLocation:
    return LabwareLocation(LocationKind.HOTEL, "", slot)


@dataclass(frozen=True)
class LabwareRecord:
    labware_id: str
    labware_type: str
    location: LabwareLocation


def observed_location(
    labware_id: str,
    handover: Handover | None,
    robot_status: RobotStatus,
    nests: Iterable[NestOccupancy],
) -> LabwareLocation:
    """Where the observations put a plate: robot hotel, gripper, a nest reporting it, or the
    hand-over nest if its sensor sees a plate without an id; otherwise unknown."""
    for slot in robot_status.hotel:
        if slot.labware_id == labware_id:
            return in_hotel(slot.index)
    if robot_status.held_labware_id == labware_id:
        return GRIPPER
    nests = tuple(nests)
    for nest in nests:
        if nest.occupied and nest.labware_id == labware_id:
            return LabwareLocation(LocationKind.STATION, nest.station, nest.sub_position)
    if handover is not None:
        for nest in nests:
            if (nest.station, nest.sub_position) == (handover.station, handover.sub_position):
                if nest.occupied and not nest.labware_id:
                    return at_station(handover)
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
        with self._lock:
            return next(
                (record for record in self._records.values() if record.location == in_hotel(slot)), None
            )

    def record(self, labware_id: str, labware_type: str, location: LabwareLocation) -> None:
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
        logger.info("labware %s is now at %s", labware_id, location)
        for listener in listeners:
            listener(snapshot)

    def settle(
        self,
        labware_id: str,
        labware_type: str,
        handover: Handover | None,
        robot_status: RobotStatus,
        nests: Iterable[NestOccupancy],
    ) -> LabwareLocation:
        """Record where the observations put the plate (after a transfer, whatever its outcome)."""
        location = observed_location(labware_id, handover, robot_status, nests)
        self.record(labware_id, labware_type, location)
        return location

    def observe_robot(self, robot_status: RobotStatus) -> None:
        """Take in plates the robot reports aboard (hotel slots, gripper) under their ids."""
        for slot in robot_status.hotel:
            if slot.labware_id:
                self.record(slot.labware_id, slot.labware_type, in_hotel(slot.index))
        if robot_status.held_labware_id:
            self.record(robot_status.held_labware_id, "", GRIPPER)
