"""The small immutable values the client takes and returns (SiLA structures, as plain Python).

Threads: any; nothing here changes after it is made.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

Address = tuple[str, int]
"""Where a SiLA server listens: (host, port)."""

Handover = tuple[str, int]
"""A handover position as the standard has it: (station name, sub-position counted from 1)."""


class HandoverPosition(NamedTuple):
    """A station the robot serves, and how many sub-positions (nests) it has."""

    position: str
    sub_positions: int


@dataclass(frozen=True)
class LabwareLocation:
    """Where the robot's inventory says a plate is: aboard in internal position `index`, or at the
    handover position `position`, sub-position `index`."""

    labware_id: str
    labware_type: str
    aboard: bool
    position: str
    index: int


@dataclass(frozen=True)
class OnboardLabware:
    """A plate the robot carries, and in which internal position (hotel slot)."""

    internal_position: int
    labware_id: str
    labware_type: str
