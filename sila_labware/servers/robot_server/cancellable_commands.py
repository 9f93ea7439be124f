"""The robot server's running observable commands, and cancelling them by execution UUID (CancelController).

What can be cancelled: the robot's commands that move it (the labware transfer commands and the base
motions), named in `CANCELLABLE_COMMANDS`. Each runs inside `running(instance)`, which binds a
`CancelToken` to the execution; cancelling marks that token and cancels the command's ROS goal
through `RobotController.cancel_command` (never by touching sila2's threads). The command then ends
as any failed command of its kind does: with its defined error (LabwareNotPicked/LabwareNotPlaced,
MotionStopped) or, for the Prepare commands, which the standard gives no such error, an undefined
execution error; each message starts with the reason of the cancel.

Which executions exist and whether they still run comes from sila2's own command managers
(`feature_servicers[...].observable_command_managers`), so an execution that was initiated but has
not reached the robot yet can be cancelled too: its token is created early and found cancelled.

Threads: `running` on the command's executor thread, `cancel`/`cancel_all` on gRPC handler threads;
one lock guards the token table.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from uuid import UUID

from sila2.framework import Feature
from sila2.framework.fully_qualified_identifier import FullyQualifiedIdentifier
from sila2.server import ObservableCommandInstance, SilaServer
from sila2.server.observables.observable_command_manager import ObservableCommandManager

from sila_labware.device.cancellation import CancelToken, cancellable
from sila_labware.device.robot_controller import RobotController

from .generated.cancelcontroller import InvalidCommandExecutionUUID, OperationNotSupported
from .generated.labwaretransfermanipulatorcontroller import LabwareTransferManipulatorControllerFeature
from .generated.mobilerobotcontroller import MobileRobotControllerFeature

logger = logging.getLogger(__name__)


def command_identifiers(feature: Feature, *commands: str) -> frozenset[FullyQualifiedIdentifier]:
    return frozenset(feature[command].fully_qualified_identifier for command in commands)


CANCELLABLE_COMMANDS = command_identifiers(
    LabwareTransferManipulatorControllerFeature,
    "PrepareForInput",
    "PrepareForOutput",
    "GetLabware",
    "PutLabware",
) | command_identifiers(MobileRobotControllerFeature, "Dock", "Undock", "DriveToPointOfInterest")
"""Every observable command of the robot server: each one moves the robot, and each can be stopped."""


class CancellableCommands:
    """Cancel tokens of the server's running executions, and the CancelController's two operations."""

    def __init__(
        self,
        server: SilaServer,
        robot: RobotController,
        cancellable_commands: Iterable[FullyQualifiedIdentifier] = CANCELLABLE_COMMANDS,
    ) -> None:
        self._server = server
        self._robot = robot
        self._cancellable = frozenset(cancellable_commands)
        self._lock = threading.Lock()
        self._tokens: dict[UUID, CancelToken] = {}
        self._in_use: set[UUID] = set()  # executions inside `running` (sila2 may not list them yet)

    @contextmanager
    def running(self, instance: ObservableCommandInstance) -> Iterator[CancelToken]:
        """Run one execution's robot command so that `cancel` can reach it."""
        token = self._token(instance.execution_uuid)
        with self._lock:
            self._in_use.add(instance.execution_uuid)
        try:
            with cancellable(token):
                yield token
        finally:
            with self._lock:
                self._in_use.discard(instance.execution_uuid)
                self._tokens.pop(instance.execution_uuid, None)

    def cancel(self, execution_uuid: UUID, reason: str) -> None:
        """Cancel one running execution.

        Raises InvalidCommandExecutionUUID when no execution with that UUID runs (never started here,
        or already finished), OperationNotSupported when its command cannot be cancelled.
        """
        manager = self._running_executions().get(execution_uuid)
        if manager is None:
            raise InvalidCommandExecutionUUID(
                f"No command with execution UUID {execution_uuid} is running on this server: "
                "the UUID is unknown here, or its command has already ended"
            )
        command = manager.wrapped_command.fully_qualified_identifier
        if command not in self._cancellable:
            raise OperationNotSupported(
                f"Execution {execution_uuid} is a {command} command, which this server cannot cancel: "
                "it has no robot motion to stop"
            )
        self._cancel(execution_uuid, manager, reason)

    def cancel_all(self, reason: str) -> list[UUID]:
        """Cancel every running execution that can be cancelled; returns their UUIDs (none: a no-op)."""
        cancelled = []
        for execution_uuid, manager in self._running_executions().items():
            command = manager.wrapped_command.fully_qualified_identifier
            if command not in self._cancellable:
                logger.warning("CancelAll: %s (%s) cannot be cancelled; it runs on", command, execution_uuid)
                continue
            self._cancel(execution_uuid, manager, reason)
            cancelled.append(execution_uuid)
        return cancelled

    def _cancel(self, execution_uuid: UUID, manager: ObservableCommandManager, reason: str) -> None:
        token = self._token(execution_uuid)
        goal_was_running = self._robot.cancel_command(token, reason)
        logger.info(
            "cancelled %s (%s)%s",
            manager.wrapped_command.fully_qualified_identifier,
            execution_uuid,
            "" if goal_was_running else "; it had no goal running, it sends none from now on",
        )
        self._forget_finished()

    def _token(self, execution_uuid: UUID) -> CancelToken:
        with self._lock:
            return self._tokens.setdefault(execution_uuid, CancelToken())

    def _forget_finished(self) -> None:
        """Drop tokens of executions that ended (a cancel can race with a command's end)."""
        running = self._running_executions()
        with self._lock:
            for execution_uuid in [uuid for uuid in self._tokens if uuid not in running]:
                if execution_uuid not in self._in_use:
                    del self._tokens[execution_uuid]

    def _running_executions(self) -> dict[UUID, ObservableCommandManager]:
        """Every observable command execution of this server that has not ended, by UUID."""
        running = {}
        for servicer in list(self._server.feature_servicers.values()):
            for managers in list(servicer.observable_command_managers.values()):
                running.update(
                    (execution_uuid, manager)
                    for execution_uuid, manager in list(managers.items())
                    if manager.is_running()
                )
        return running
