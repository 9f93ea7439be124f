"""Check command parameters against what the workcell offers, with errors that name the problem.

The sila2 library already enforces the feature's own constraints (PositionIndex >= 1); what it
cannot know is this workcell: which stations exist, how many nests each has, how many hotel
slots the robot carries, which intermediate actions it supports.

Empty LabwareType and LabwareUniqueID are accepted on purpose: real schedulers often send
them empty (the robot then tracks the plate under the id the robot side reports).
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field

from labware_model.holders import Nest
from sila_labware.device.errors import ParameterError

MAX_TEXT_LENGTH = 255


def check_text(value: str, parameter: str, *, allow_empty: bool) -> str:
    """Refuse empty (unless allowed), oversized or control-character strings."""
    if not value and not allow_empty:
        raise ParameterError(parameter, f"{parameter} must not be empty")
    if len(value) > MAX_TEXT_LENGTH:
        raise ParameterError(
            parameter, f"{parameter} is {len(value)} characters long; at most {MAX_TEXT_LENGTH} are allowed"
        )
    if any(ord(character) < 32 for character in value):
        raise ParameterError(parameter, f"{parameter} contains control characters")
    return value


def check_handover(
    position: str,
    sub_position: int,
    sub_positions_by_station: Mapping[str, int],
    parameter: str = "HandoverPosition",
) -> Nest:
    """The named station must exist and have at least `sub_position` nests; returns that nest."""
    check_text(position, parameter, allow_empty=False)
    if position not in sub_positions_by_station:
        known = ", ".join(sorted(sub_positions_by_station)) or "none"
        raise ParameterError(parameter, f"unknown handover position {position!r}; known positions: {known}")
    count = sub_positions_by_station[position]
    if not 1 <= sub_position <= count:
        raise ParameterError(
            parameter,
            f"SubPosition {sub_position} is beyond handover position {position!r}, "
            f"which has {count} sub-position{'s' if count != 1 else ''} (1..{count})",
        )
    return Nest(position, sub_position)


def check_internal_position(index: int, count: int, parameter: str = "InternalPosition") -> int:
    """A 1-based internal position (hotel slot) that exists on this device."""
    if not 1 <= index <= count:
        raise ParameterError(
            parameter,
            f"InternalPosition {index} is beyond this device's {count} internal positions (1..{count})",
        )
    return index


def check_intermediate_actions(
    actions: Sequence[str], available: Collection[str], parameter: str = "IntermediateActions"
) -> tuple[str, ...]:
    """Every requested intermediate action must be one the device offers."""
    for action in actions:
        check_text(action, parameter, allow_empty=False)
        if action not in available:
            offered = ", ".join(sorted(available)) or "none"
            raise ParameterError(
                parameter, f"unknown intermediate action {action!r}; this device offers: {offered}"
            )
    return tuple(actions)


@dataclass(frozen=True)
class DeviceParameters:
    """What one device offers, and the checks of each command's parameters against it.

    The checks need no motion and no device state, so the SiLA servers also run them on the
    initiating call of a command (servers.initiation_checks), and each command runs them again.
    All raise ParameterError naming the parameter."""

    sub_positions: Mapping[str, int]
    """Hand-over position (station) -> number of its nests."""
    internal_positions: int
    points_of_interest: tuple[str, ...] = ()
    intermediate_actions: tuple[str, ...] = field(default=())

    def handover(self, position: str, sub_position: int) -> Nest:
        return check_handover(position, sub_position, self.sub_positions)

    def prepare(
        self,
        position: str,
        sub_position: int,
        internal_position: int,
        labware_type: str = "",
        labware_id: str = "",
    ) -> Nest:
        """PrepareForInput/PrepareForOutput: a nest this device serves, an internal position it
        has, labware type and id it can record (either may be empty)."""
        nest = self.handover(position, sub_position)
        check_internal_position(internal_position, self.internal_positions)
        check_text(labware_type, "LabwareType", allow_empty=True)
        check_text(labware_id, "LabwareUniqueID", allow_empty=True)
        return nest

    def transfer(self, position: str, sub_position: int, intermediate_actions: Sequence[str]) -> Nest:
        """GetLabware/PutLabware: a nest this device serves, intermediate actions it offers."""
        nest = self.handover(position, sub_position)
        check_intermediate_actions(intermediate_actions, self.intermediate_actions)
        return nest

    def point_of_interest(self, poi: str) -> str:
        """DriveToPointOfInterest: a point of interest of this workcell."""
        check_text(poi, "PointOfInterest", allow_empty=False)
        if poi not in self.points_of_interest:
            known = ", ".join(self.points_of_interest) or "none"
            raise ParameterError("PointOfInterest", f"no point of interest {poi!r}; known: {known}")
        return poi
