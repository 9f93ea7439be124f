"""A station's behaviour behind its LabwareTransferSiteController: a digital twin of a passive device.

The twin keeps the protocol order per nest (`SiteSequence`) and takes occupancy from the
station's nest sensors as the robot side publishes them on /station_states. Decisions it makes
from that sensor (documented for clients):

- PrepareForInput is refused with InvalidCommandSequence while the nest is occupied;
- PrepareForOutput is refused with InvalidCommandSequence while the nest is empty;
- LabwareDelivered / LabwareRemoved are refused with InvalidCommandSequence if, within
  `settle_timeout_s`, the sensor does not confirm the plate arrived / left. The nest then stays
  prepared, so the client may send the command again once the plate is really there / gone.

A station has no internal positions of its own; InternalPosition must be 1 (the standard's rule
for devices without internal positions).

Its back end is a `StationBackend` (robot_backend.py): the nest sensors, read through the ROS
bridge's `RobotLink` in a deployment.

Threads: methods run on SiLA handler threads and only read the back end's sensor mirror.
"""

from __future__ import annotations

import logging

from labware_model.holders import Nest
from labware_model.readings import NestReading
from labware_model.workcell import StationDescription
from ros_bridge.errors import BridgeTimeout
from sila_labware.device.errors import CommandSequenceError
from sila_labware.device.robot_backend import StationBackend
from sila_labware.device.sequences import NestExpectation, NestPhase, SiteSequence
from sila_labware.device.validation import DeviceParameters

logger = logging.getLogger(__name__)

STATION_INTERNAL_POSITIONS = 1


class StationController:
    """One station: its name, its nests, and their protocol state."""

    def __init__(
        self, link: StationBackend, station: StationDescription, settle_timeout_s: float = 5.0
    ) -> None:
        self.link = link
        self.station = station
        self.settle_timeout_s = settle_timeout_s
        self.sequence = SiteSequence(station.name, station.sub_positions)
        self.parameters = DeviceParameters({station.name: station.sub_positions}, STATION_INTERNAL_POSITIONS)

    def handover_positions(self) -> list[tuple[str, int]]:
        return [(self.station.name, self.station.sub_positions)]

    @property
    def internal_positions(self) -> int:
        return STATION_INTERNAL_POSITIONS

    def prepare_for_input(
        self, position: str, sub_position: int, internal_position: int, labware_type: str, labware_id: str
    ) -> None:
        sub_position = self.parameters.prepare(
            position, sub_position, internal_position, labware_type, labware_id
        ).sub_position
        occupied = self.nest_reading(sub_position).occupied
        self.sequence.prepare_for_input(sub_position, internal_position, labware_type, labware_id, occupied)

    def prepare_for_output(self, position: str, sub_position: int, internal_position: int) -> None:
        sub_position = self.parameters.prepare(position, sub_position, internal_position).sub_position
        occupied = self.nest_reading(sub_position).occupied
        self.sequence.prepare_for_output(sub_position, internal_position, occupied)

    def labware_delivered(self, position: str, sub_position: int) -> NestExpectation:
        sub_position = self.parameters.handover(position, sub_position).sub_position
        self._require_phase_then_sensor(sub_position, "LabwareDelivered", want_occupied=True)
        return self.sequence.labware_delivered(sub_position)

    def labware_removed(self, position: str, sub_position: int) -> NestExpectation:
        sub_position = self.parameters.handover(position, sub_position).sub_position
        self._require_phase_then_sensor(sub_position, "LabwareRemoved", want_occupied=False)
        return self.sequence.labware_removed(sub_position)

    def nest_reading(self, sub_position: int) -> NestReading:
        """The sensor reading of one nest (a nest missing from the report counts as empty)."""
        nest = Nest(self.station.name, sub_position)
        for reading in self.link.nest_readings():
            if reading.nest == nest:
                return reading
        logger.warning("no sensor reading for %s; treating it as empty", nest)
        return NestReading(nest, False, "")

    def _require_phase_then_sensor(self, sub_position: int, command: str, want_occupied: bool) -> None:
        # Order first (a wrong order is reported as such, without waiting for the sensor).
        required = NestPhase.PREPARED_FOR_INPUT if want_occupied else NestPhase.PREPARED_FOR_OUTPUT
        if self.sequence.nest(sub_position).phase is not required:
            if want_occupied:
                self.sequence.labware_delivered(sub_position)  # raises the ordering error
            else:
                self.sequence.labware_removed(sub_position)
        nest = Nest(self.station.name, sub_position)
        try:
            self.link.wait_for_nest(nest, want_occupied, self.settle_timeout_s)
        except BridgeTimeout as error:
            state = "still sees no plate" if want_occupied else "still sees a plate"
            raise CommandSequenceError(
                f"{command} refused: the sensor of nest {nest} {state} after {self.settle_timeout_s:.0f} s"
            ) from error
