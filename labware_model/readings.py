"""What the sensors and the physics report about holders and plates, as plain values.

Why here: the simulation's sensors produce these, the ROS messages carry them, and the SiLA side
decides from them; one type each keeps the three in step. Frozen; safe on any thread.
"""

from __future__ import annotations

from dataclasses import dataclass

from labware_model.holders import HotelSlot, Location, Nest


@dataclass(frozen=True)
class NestReading:
    """A nest's presence sensor: whether a plate is there, and its id when the sensor can read it
    ("" otherwise, even while occupied)."""

    nest: Nest
    occupied: bool
    labware_id: str = ""


@dataclass(frozen=True)
class HotelSlotReading:
    """A hotel pocket's sensors: whether a plate is there (presence) and, when its reader read the
    label, the plate's id and type name ("" otherwise). An id implies presence."""

    slot: HotelSlot
    labware_id: str = ""
    labware_type: str = ""
    occupied: bool = False

    def __post_init__(self) -> None:
        if self.labware_id and not self.occupied:
            object.__setattr__(self, "occupied", True)

    @property
    def unread(self) -> bool:
        """A plate is there whose label the reader could not read."""
        return self.occupied and not self.labware_id


@dataclass(frozen=True)
class PlacementCheck:
    """The physics' ground truth about one plate: for success checks only, never for robot control.

    `found`: the plate exists. `location`: where it is (any `Location`, `FLOOR` included).
    `in_nest`: it rests in the nest that was asked about, within that nest's tolerance;
    `position_error_m` and `yaw_error_rad` measure it against that nest's site (NaN when no nest
    was asked about, infinite when the plate was not found); `outside`: when the plate is in the
    asked nest but not `in_nest`, every limit it missed, in words.
    """

    found: bool
    in_nest: bool
    position_error_m: float
    yaw_error_rad: float
    location: Location
    outside: str = ""
