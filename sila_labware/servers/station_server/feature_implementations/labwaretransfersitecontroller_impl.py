"""LabwareTransferSiteController (SiLA labware transfer v1.0, passive side) for one station.

Behaviour lives in `sila_labware.device.station_controller.StationController` (a digital twin fed by
the station's nest sensors); this file only translates parameters and errors. Refusals, all as
the standard's InvalidCommandSequence: PrepareForInput while the nest is occupied,
PrepareForOutput while it is empty, LabwareDelivered/LabwareRemoved out of order or before the
sensor confirms the plate arrived/left.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from sila2.server import MetadataDict, ObservableCommandInstance

from sila_labware.device.errors import CommandSequenceError, ParameterError
from sila_labware.servers.sila_glue import handover_position, validation_error

from ..generated.labwaretransfersitecontroller import (
    HandoverPosition,
    InvalidCommandSequence,
    LabwareDelivered_Responses,
    LabwareRemoved_Responses,
    LabwareTransferSiteControllerBase,
    LabwareTransferSiteControllerFeature,
    PositionIndex,
    PrepareForInput_Responses,
    PrepareForOutput_Responses,
)

if TYPE_CHECKING:
    from ..server import Server


class LabwareTransferSiteControllerImpl(LabwareTransferSiteControllerBase):
    def __init__(self, parent_server: Server) -> None:
        super().__init__(parent_server=parent_server)
        self.station = parent_server.station

    def get_AvailableHandoverPositions(self, *, metadata: MetadataDict) -> list[HandoverPosition]:
        return [handover_position(name, count) for name, count in self.station.handover_positions()]

    def get_NumberOfInternalPositions(self, *, metadata: MetadataDict) -> int:
        return self.station.internal_positions

    def PrepareForInput(
        self,
        HandoverPosition: HandoverPosition,
        InternalPosition: PositionIndex,
        LabwareType: str,
        LabwareUniqueID: str,
        *,
        metadata: MetadataDict,
        instance: ObservableCommandInstance,
    ) -> PrepareForInput_Responses:
        instance.begin_execution()
        self._run(
            "PrepareForInput",
            lambda: self.station.prepare_for_input(
                HandoverPosition.Position,
                HandoverPosition.SubPosition,
                InternalPosition,
                LabwareType,
                LabwareUniqueID,
            ),
        )
        return PrepareForInput_Responses()

    def PrepareForOutput(
        self,
        HandoverPosition: HandoverPosition,
        InternalPosition: PositionIndex,
        *,
        metadata: MetadataDict,
        instance: ObservableCommandInstance,
    ) -> PrepareForOutput_Responses:
        instance.begin_execution()
        self._run(
            "PrepareForOutput",
            lambda: self.station.prepare_for_output(
                HandoverPosition.Position, HandoverPosition.SubPosition, InternalPosition
            ),
        )
        return PrepareForOutput_Responses()

    def LabwareDelivered(
        self,
        HandoverPosition: HandoverPosition,
        *,
        metadata: MetadataDict,
        instance: ObservableCommandInstance,
    ) -> LabwareDelivered_Responses:
        instance.begin_execution()
        self._run(
            "LabwareDelivered",
            lambda: self.station.labware_delivered(HandoverPosition.Position, HandoverPosition.SubPosition),
        )
        return LabwareDelivered_Responses()

    def LabwareRemoved(
        self,
        HandoverPosition: HandoverPosition,
        *,
        metadata: MetadataDict,
        instance: ObservableCommandInstance,
    ) -> LabwareRemoved_Responses:
        instance.begin_execution()
        self._run(
            "LabwareRemoved",
            lambda: self.station.labware_removed(HandoverPosition.Position, HandoverPosition.SubPosition),
        )
        return LabwareRemoved_Responses()

    def _run(self, command: str, action: Callable[[], object]) -> None:
        try:
            action()
        except CommandSequenceError as error:
            raise InvalidCommandSequence(str(error)) from error
        except ParameterError as error:
            raise validation_error(LabwareTransferSiteControllerFeature, command, error) from error
