"""LabwareTransferManipulatorController (SiLA labware transfer v1.0, active side) for the robot.

Behaviour lives in `sila_labware.device.robot_controller.RobotController`; this file only translates:
parameters in, progress out, exceptions into the standard's errors. Every command runs under its
execution's cancel token (`cancellable_commands`), so CancelController can stop it. Handler threads
block on the robot's ROS goals (futures with timeouts), never on the ROS executor.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TYPE_CHECKING, TypeVar

from sila2.server import MetadataDict, ObservableCommandInstance

from sila_labware.device.errors import CommandSequenceError, MotionFailed, ParameterError, TransferFailed
from sila_labware.device.robot_controller import INTERMEDIATE_ACTIONS
from sila_labware.servers.sila_glue import (
    handover_position,
    progress_reporter,
    validation_error,
)

from ..generated.labwaretransfermanipulatorcontroller import (
    GetLabware_Responses,
    HandoverPosition,
    InvalidCommandSequence,
    LabwareNotPicked,
    LabwareNotPlaced,
    LabwareTransferManipulatorControllerBase,
    LabwareTransferManipulatorControllerFeature,
    PositionIndex,
    PrepareForInput_Responses,
    PrepareForOutput_Responses,
    PutLabware_Responses,
)

if TYPE_CHECKING:
    from ..server import Server

logger = logging.getLogger(__name__)

T = TypeVar("T")


class LabwareTransferManipulatorControllerImpl(LabwareTransferManipulatorControllerBase):
    def __init__(self, parent_server: Server) -> None:
        super().__init__(parent_server=parent_server)
        self.robot = parent_server.robot
        self.commands = parent_server.cancellable_commands

    def get_AvailableHandoverPositions(self, *, metadata: MetadataDict) -> list[HandoverPosition]:
        return [handover_position(name, count) for name, count in self.robot.handover_positions()]

    def get_NumberOfInternalPositions(self, *, metadata: MetadataDict) -> int:
        return self.robot.internal_positions

    def get_AvailableIntermediateActions(self, *, metadata: MetadataDict) -> list[str]:
        return list(INTERMEDIATE_ACTIONS)

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
            instance,
            lambda: self.robot.prepare_for_input(
                HandoverPosition.Position,
                HandoverPosition.SubPosition,
                InternalPosition,
                LabwareType,
                LabwareUniqueID,
                progress_reporter(instance),
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
            instance,
            lambda: self.robot.prepare_for_output(
                HandoverPosition.Position,
                HandoverPosition.SubPosition,
                InternalPosition,
                progress_reporter(instance),
            ),
        )
        return PrepareForOutput_Responses()

    def PutLabware(
        self,
        HandoverPosition: HandoverPosition,
        IntermediateActions: list[str],
        *,
        metadata: MetadataDict,
        instance: ObservableCommandInstance,
    ) -> PutLabware_Responses:
        self._transfer("PutLabware", HandoverPosition, IntermediateActions, instance, LabwareNotPlaced)
        return PutLabware_Responses()

    def GetLabware(
        self,
        HandoverPosition: HandoverPosition,
        IntermediateActions: list[str],
        *,
        metadata: MetadataDict,
        instance: ObservableCommandInstance,
    ) -> GetLabware_Responses:
        self._transfer("GetLabware", HandoverPosition, IntermediateActions, instance, LabwareNotPicked)
        return GetLabware_Responses()

    def _transfer(
        self,
        command: str,
        handover: HandoverPosition,
        intermediate_actions: list[str],
        instance: ObservableCommandInstance,
        failed: Callable[[str], Exception],
    ) -> None:
        """Run GetLabware/PutLabware; a failed transfer becomes the command's own defined error."""
        instance.begin_execution()
        method = self.robot.get_labware if command == "GetLabware" else self.robot.put_labware
        try:
            self._run(
                command,
                instance,
                lambda: method(
                    handover.Position,
                    handover.SubPosition,
                    list(intermediate_actions),
                    progress_reporter(instance),
                ),
            )
        except TransferFailed as failure:
            raise failed(failure.message) from failure

    def _run(self, command: str, instance: ObservableCommandInstance, action: Callable[[], T]) -> T:
        """Run under the execution's cancel token and translate the logic's errors; TransferFailed is
        left to the caller (it knows which error)."""
        try:
            with self.commands.running(instance):
                return action()
        except CommandSequenceError as error:
            raise InvalidCommandSequence(str(error)) from error
        except ParameterError as error:
            raise validation_error(LabwareTransferManipulatorControllerFeature, command, error) from error
        except MotionFailed as error:
            if command.startswith("Prepare"):
                # The standard gives Prepare* one defined error. A drive that did not arrive (blocked,
                # a collision, a cancel) leaves nothing prepared: the handover cannot go on in this
                # order, and a GetLabware/PutLabware now would be refused the same way.
                raise InvalidCommandSequence(
                    f"{command} could not bring the robot to the handover position, so nothing is "
                    f"prepared: {error.message}; the robot stands where it stopped"
                ) from error
            raise TransferFailed(error.error_code, error.message) from error  # the command's own error
