"""The small immutable values the client takes and returns (SiLA structures, as plain Python).

Threads: any; nothing here changes after it is made.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

from labware_model.holders import GRIPPER, UNKNOWN, HotelSlot, Location, Nest

Address = tuple[str, int]
"""Where a SiLA server listens: (host, port)."""

Handover = Nest | tuple[str, int]
"""A handover position: a labware-model `Nest`, or the standard's (station name, sub-position
counted from 1) as a plain pair."""


class HandoverPosition(NamedTuple):
    """A station the robot serves, and how many sub-positions (nests) it has."""

    position: str
    sub_positions: int


@dataclass(frozen=True)
class LabwareLocation:
    """Where the robot's inventory says a plate is, in the labware model's words: a `Nest`, a
    `HotelSlot` (the robot's internal position), the gripper, or unknown."""

    labware_id: str
    labware_type: str
    location: Location

    @property
    def aboard(self) -> bool:
        return isinstance(self.location, HotelSlot) or self.location == GRIPPER

    @classmethod
    def from_sila(
        cls,
        labware_id: str,
        labware_type: str,
        aboard: bool,
        position: str,
        index: int,
        internal_positions: int,
    ) -> LabwareLocation:
        """From LabwareInventory's structure: aboard, Index is the internal position (one past the
        last stands for the gripper); at a station, Position and Index name the nest."""
        if not aboard:
            return cls(labware_id, labware_type, Nest(position, index) if position else UNKNOWN)
        return cls(labware_id, labware_type, GRIPPER if index > internal_positions else HotelSlot(index))


@dataclass(frozen=True)
class OnboardLabware:
    """A plate the robot carries, and in which internal position (hotel slot)."""

    internal_position: int
    labware_id: str
    labware_type: str
