"""What the robot side serves: its stations with their nests, its hotel slots, its POIs.

Why here: /describe_workcell reports this once, and both the SiLA side (through the ROS bridge)
and the robot's task sequencer read it; the world file is where it comes from. Names only, no
geometry. Frozen; safe on any thread.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class StationDescription:
    """A station the robot serves: its name, how many nests it has (`Nest`s with sub-positions
    1..n) and the point of interest the robot works from."""

    name: str
    sub_positions: int
    poi: str

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"a station needs a name, got {self.name!r}")
        if isinstance(self.sub_positions, bool) or not isinstance(self.sub_positions, int):
            raise ValueError(f"station {self.name!r}: sub_positions must be an integer")
        if self.sub_positions < 1:
            raise ValueError(f"station {self.name!r} needs at least one nest, got {self.sub_positions}")


@dataclass(frozen=True)
class WorkcellDescription:
    """Everything the robot can serve, as the world file describes it: the stations, the number of
    hotel slots (`HotelSlot`s 1..n), every POI, and the POI in front of the dock."""

    stations: tuple[StationDescription, ...]
    hotel_slots: int
    pois: tuple[str, ...]
    dock_poi: str

    def station(self, name: str) -> StationDescription | None:
        return next((station for station in self.stations if station.name == name), None)
