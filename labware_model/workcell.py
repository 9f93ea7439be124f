"""What the robot side serves: its stations with their nests, its hotel slots, its POIs.

Why here: /describe_workcell reports this once, and both the SiLA side (through the ROS bridge)
and the robot's task sequencer read it; the world file is where it comes from. Names only, no
geometry. Frozen; safe on any thread.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


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
class LabSensors:
    """Which lab-added plate sensors the robot's checks may read. A stock TIAGo++ has none of them:
    it checks a nest with its head camera's depth image and its hotel with the fingers' gap as it
    lets go, and names plates by the scheduler's words (docs/explanation/sensors.md)."""

    nests: bool = True  # a presence sensor in every nest, on /station_states
    hotel: bool = True  # a presence sensor in every onboard hotel pocket, on /robot_state
    label_readers: bool = True  # barcode readers at nests and pockets and in the palm

    def names(self) -> tuple[str, ...]:
        """The sensors present, in words (for logs and messages)."""
        return tuple(name for name in ("nests", "hotel", "label_readers") if getattr(self, name))


STOCK_SENSORS = LabSensors(nests=False, hotel=False, label_readers=False)


@dataclass(frozen=True)
class WorkcellDescription:
    """Everything the robot can serve, as the world file describes it: the stations, the number of
    hotel slots (`HotelSlot`s 1..n), every POI, the POI in front of the dock, and which lab-added
    plate sensors there are."""

    stations: tuple[StationDescription, ...]
    hotel_slots: int
    pois: tuple[str, ...]
    dock_poi: str
    sensors: LabSensors = LabSensors()

    @classmethod
    def from_message(cls, response: Any) -> WorkcellDescription:
        """From a DescribeWorkcell response (read by its fields: no ROS import here)."""
        return cls(
            stations=tuple(
                StationDescription(s.name, int(s.sub_positions), s.poi) for s in response.stations
            ),
            hotel_slots=int(response.hotel_slots),
            pois=tuple(response.pois),
            dock_poi=response.dock_poi,
            sensors=LabSensors(
                bool(response.nest_sensors), bool(response.hotel_sensors), bool(response.label_readers)
            ),
        )

    def station(self, name: str) -> StationDescription | None:
        return next((station for station in self.stations if station.name == name), None)
