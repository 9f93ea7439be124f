"""Plain-Python views of what the robot side reports, so layers above never touch ROS messages.

These are immutable snapshots built from labware_interfaces messages (see `robot_link.py`);
they hold SI units (m, rad) like the messages they come from. Nests, hotel slots and the
readings of their sensors are the labware model's (`labware_model`); the workcell the robot
serves is its `WorkcellDescription`.
"""

from __future__ import annotations

from dataclasses import dataclass

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

    @property
    def docked(self) -> bool:
        return self.state == "docked"

    @property
    def onboard_labware_ids(self) -> tuple[str, ...]:
        held = (self.held_labware_id,) if self.held_labware_id else ()
        return tuple(slot.labware_id for slot in self.hotel if slot.labware_id) + held
