"""The robot side's inventory as this server last received it: a mirror, never a second truth.

Why a mirror: the inventory is held where the sensors are (the robot side's task sequencer, see
labware_model.inventory), because every transfer runs there whichever door it came through (this
SiLA server, the Bluesky device, any ROS client). The SiLA features read this mirror; it changes
only when the robot side publishes (`replace`), or when the deployment's supervisor finds the
robot side gone (`mark_all_unknown`, until the restarted robot side publishes again).

Thread-safe (one lock); change listeners run on the thread that made the change.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from dataclasses import replace

from labware_model.holders import UNKNOWN, HotelSlot, Location, location_text
from labware_model.inventory import LabwareRecord
from ros_bridge.workcell import InventorySnapshot

logger = logging.getLogger(__name__)

__all__ = ["Inventory", "LabwareRecord"]


class Inventory:
    """LabwareUniqueID -> type and location, as the robot side published them last."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._snapshot = InventorySnapshot(0, ())
        self._listeners: list[Callable[[tuple[LabwareRecord, ...]], None]] = []

    def add_listener(self, listener: Callable[[tuple[LabwareRecord, ...]], None]) -> None:
        with self._lock:
            self._listeners.append(listener)

    @property
    def revision(self) -> int:
        with self._lock:
            return self._snapshot.revision

    def locate(self, labware_id: str) -> LabwareRecord | None:
        with self._lock:
            return next((r for r in self._snapshot.records if r.labware_id == labware_id), None)

    def records(self) -> tuple[LabwareRecord, ...]:
        with self._lock:
            return self._snapshot.records

    def at(self, location: Location) -> LabwareRecord | None:
        """The plate recorded at `location` (a nest, a hotel slot, the gripper), if any."""
        with self._lock:
            return next((r for r in self._snapshot.records if r.location == location), None)

    def in_hotel_slot(self, slot: int) -> LabwareRecord | None:
        """The plate recorded in hotel slot `slot` (1-based), if any."""
        return self.at(HotelSlot(slot))

    def replace(self, snapshot: InventorySnapshot) -> None:
        """Take the robot side's latest inventory; listeners hear of a change of records."""
        with self._lock:
            changed = snapshot.records != self._snapshot.records
            self._snapshot = snapshot
            listeners = list(self._listeners) if changed else []
        if changed:
            for record in snapshot.records:
                logger.debug("labware %s at %s", record.labware_id, location_text(record.location))
        for listener in listeners:
            listener(snapshot.records)

    def mark_all_unknown(self) -> None:
        """The robot side is gone: no sensor vouches for any plate until it publishes again."""
        with self._lock:
            snapshot = self._snapshot
        records = tuple(replace(record, location=UNKNOWN) for record in snapshot.records)
        self.replace(InventorySnapshot(snapshot.revision, records))
