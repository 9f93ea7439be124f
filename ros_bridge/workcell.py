"""Plain-Python views of what the robot side reports, so layers above never touch ROS messages.

These are immutable snapshots built from labware_interfaces messages (see `robot_link.py`),
plus the one request the layers above build (`LabwareHandover`, what a GetLabware/PutLabware goal
carries); they hold SI units (m, rad) like the messages they come from. Nests, hotel slots and the
readings of their sensors are the labware model's (`labware_model`); the workcell the robot
serves is its `WorkcellDescription`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

from labware_model.holders import HotelSlot, Nest
from labware_model.inventory import LabwareRecord
from labware_model.readings import HotelSlotReading


@dataclass(frozen=True)
class RobotStatus:
    """One /robot_state message: state word, where the base is, what the robot carries."""

    state: str
    detail: str
    current_poi: str
    x_m: float
    y_m: float
    theta_rad: float
    hotel: tuple[HotelSlotReading, ...]
    held_labware_id: str
    stamp_s: float = 0.0
    """The message stamp in seconds: the robot side's clock (simulated time in simulation)."""
    holding: bool = False
    """The gripper holds a plate (presence), read or not; a held id implies it."""

    # the state words of labware_interfaces/RobotState
    DOCKED: ClassVar[str] = "docked"
    IDLE: ClassVar[str] = "idle"

    def __post_init__(self) -> None:
        if self.held_labware_id and not self.holding:
            object.__setattr__(self, "holding", True)

    @property
    def docked(self) -> bool:
        return self.state == self.DOCKED

    @property
    def at_rest(self) -> bool:
        """Nothing moves: standing idle, or docked."""
        return self.state in (self.IDLE, self.DOCKED)

    @property
    def onboard_labware_ids(self) -> tuple[str, ...]:
        held = (self.held_labware_id,) if self.held_labware_id else ()
        return tuple(slot.labware_id for slot in self.hotel if slot.labware_id) + held


@dataclass(frozen=True)
class InventorySnapshot:
    """One /labware_inventory message: the robot side's named plates and where its sensors put
    them (labware_model.inventory), with the revision that grows with every change."""

    revision: int
    records: tuple[LabwareRecord, ...]


@dataclass(frozen=True)
class LabwareHandover:
    """What GetLabware and PutLabware goals carry: the station nest, the robot's hotel slot, the
    plate's type and id, the intermediate actions to run."""

    nest: Nest
    hotel_slot: HotelSlot
    labware_type: str
    labware_id: str
    intermediate_actions: Sequence[str] = ()

    def goal(self, goal_type: Callable[..., Any]) -> Any:
        return goal_type(
            handover_position=self.nest.station,
            sub_position=self.nest.sub_position,
            internal_position=self.hotel_slot.index,
            labware_type=self.labware_type,
            labware_id=self.labware_id,
            intermediate_actions=list(self.intermediate_actions),
        )
