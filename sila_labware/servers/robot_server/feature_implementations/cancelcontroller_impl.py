"""CancelController (SiLA core, org.silastandard/core.commands/CancelController/v1) for the robot.

The work is done by the server's `CancellableCommands` (see `cancellable_commands`): it finds the
execution among sila2's command managers, and cancels the robot command through its token. Both
calls return as soon as the cancel is requested; the cancelled command itself ends a moment later,
once the robot side confirmed its goal cancelled and the inventory was settled.

CancelAll also covers unobservable commands in principle; this server's (StopMotion, LocateLabware,
the property reads) return at once, so there is never one to cancel.
"""

from __future__ import annotations

from typing import TYPE_CHECKING
from uuid import UUID

from sila2.server import MetadataDict

from ..generated.cancelcontroller import CancelAll_Responses, CancelCommand_Responses, CancelControllerBase

if TYPE_CHECKING:
    from ..server import Server


class CancelControllerImpl(CancelControllerBase):
    def __init__(self, parent_server: Server) -> None:
        super().__init__(parent_server=parent_server)
        self.commands = parent_server.cancellable_commands

    def CancelCommand(self, CommandExecutionUUID: str, *, metadata: MetadataDict) -> CancelCommand_Responses:
        # The parameter's pattern (checked by sila2 before this runs) makes it a valid UUID string.
        self.commands.cancel(
            UUID(CommandExecutionUUID), "cancelled by a client (CancelController.CancelCommand)"
        )
        return CancelCommand_Responses()

    def CancelAll(self, *, metadata: MetadataDict) -> CancelAll_Responses:
        self.commands.cancel_all("cancelled by a client (CancelController.CancelAll)")
        return CancelAll_Responses()
