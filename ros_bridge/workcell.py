"""Plain-Python views of what the robot side reports, so layers above never touch ROS messages.

These are immutable snapshots built from labware_interfaces messages (see `robot_link.py`),
plus the one request the layers above build (`LabwareHandover`, what a GetLabware/PutLabware goal
carries); they hold SI units (m, rad) like the messages they come from.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class StationDescription:
    """A station the robot serves: its name, number of nests and the POI to work from."""

    name: str
    sub_positions: int
    poi: str


@dataclass(frozen=True)
class WorkcellDescription:
    """Everything the robot can serve, as the world file describes it."""

    stations: tuple[StationDescription, ...]
    hotel_slots: int
    pois: tuple[str, ...]
    dock_poi: str

    def station(self, name: str) -> StationDescription | None:
        return next((station for station in self.stations if station.name == name), None)


@dataclass(frozen=True)
class HotelSlotContent:
    index: int
    labware_id: str
    labware_type: str


@dataclass(frozen=True)
class RobotStatus:
    """One /robot_state message: state word, where the base is, what the robot carries."""

    state: str
    detail: str
    current_poi: str
    x_m: float
    y_m: float
    theta_rad: float
    hotel: tuple[HotelSlotContent, ...]
    held_labware_id: str
    stamp_s: float = 0.0
    """The message stamp in seconds: the robot side's clock (simulated time in simulation)."""

    @property
    def docked(self) -> bool:
        return self.state == "docked"

    @property
    def onboard_labware_ids(self) -> tuple[str, ...]:
        held = (self.held_labware_id,) if self.held_labware_id else ()
        return tuple(slot.labware_id for slot in self.hotel if slot.labware_id) + held


@dataclass(frozen=True)
class NestOccupancy:
    """One nest of a station, as the station's sensor reports it."""

    station: str
    sub_position: int
    occupied: bool
    labware_id: str


@dataclass(frozen=True)
class PlacementCheck:
    """Physics ground truth about one plate (for success checks only, never for control)."""

    found: bool
    in_nest: bool
    position_error_m: float
    yaw_error_rad: float
    location: str
    outside: str = ""  # in the expected nest but outside its tolerance: the limits it missed


@dataclass(frozen=True)
class LabwareHandover:
    """What GetLabware and PutLabware goals carry: the station nest (1-based sub-position), the
    robot's hotel slot (1-based), the plate's type and id, the intermediate actions to run."""

    station: str
    sub_position: int
    hotel_slot: int
    labware_type: str
    labware_id: str
    intermediate_actions: Sequence[str] = ()

    def goal(self, goal_type: Callable[..., Any]) -> Any:
        return goal_type(
            handover_position=self.station,
            sub_position=self.sub_position,
            internal_position=self.hotel_slot,
            labware_type=self.labware_type,
            labware_id=self.labware_id,
            intermediate_actions=list(self.intermediate_actions),
        )
