"""Typed exceptions of `LabwareTransferClient`: one class per error a server can define, and a few more.

Why typed: a scheduler reacts differently to "wrong order" (a bug in the caller, or another
client got there first), "the plate was not picked" (send a person) and "the server is gone"
(reconnect). sila2's plain client raises one `DefinedExecutionError` for all of them, told apart
only by an identifier string; here each defined error of the features the robot and the stations
serve is its own subclass of `DefinedError`, so `except LabwareNotPicked:` works.

Every exception carries `command` (which command failed, as "Robot.GetLabware" or
"station_a.PrepareForOutput"), `step` (which step of the client's sequence was running, see
`sila_labware.client.steps`) and `message` (the server's own words, which for the robot's motion
failures include the robot side's error code, e.g. "(MARKER_NOT_FOUND)").

    LabwareTransferError                 base of everything the client raises
    +-- DefinedError                     a defined execution error; `identifier` names it
    |   +-- InvalidCommandSequence       both labware transfer features
    |   +-- LabwareNotPicked, LabwareNotPlaced           manipulator
    |   +-- UnknownPointOfInterest, NavigationFailed, DockingFailed, UndockingFailed,
    |   |   RobotDocked, RobotBusy, MotionStopped        MobileRobotController
    |   +-- UnknownLabware               LabwareInventory
    +-- ParameterRejected                a validation error; `parameter` names the parameter
    +-- UndefinedServerError             the server failed in a way no feature defines
    +-- StepTimeout (also TimeoutError)  a step did not end within the client's timeout
    +-- ServerUnreachable (also ConnectionError)

A defined error whose identifier is not in the table above (a server with more features) is
raised as `DefinedError` itself, with its identifier.

Threads: any; `translate` is pure.
"""

from __future__ import annotations

from sila2.framework import (
    DefinedExecutionError,
    FrameworkError,
    SilaConnectionError,
    UndefinedExecutionError,
    ValidationError,
)


class LabwareTransferError(Exception):
    """Base of every error the client raises."""

    def __init__(self, message: str, *, command: str = "", step: str = "") -> None:
        self.message = message
        self.command = command
        self.step = step
        super().__init__(self._describe())

    def _describe(self) -> str:
        if not self.command:
            return self.message
        where = self.command if self.step in ("", self.command) else f"{self.command} (step {self.step})"
        return f"{where}: {self.message}"


class DefinedError(LabwareTransferError):
    """A defined execution error of a SiLA feature; subclasses name the specific one."""

    identifier: str = ""

    def __init__(self, message: str, *, command: str = "", step: str = "", identifier: str = "") -> None:
        if identifier:
            self.identifier = identifier
        super().__init__(message, command=command, step=step)


class InvalidCommandSequence(DefinedError):
    """The command came in an order the labware transfer protocol does not allow."""

    identifier = "InvalidCommandSequence"


class LabwareNotPicked(DefinedError):
    """GetLabware did not take the plate; the message says why (robot side's error code first)."""

    identifier = "LabwareNotPicked"


class LabwareNotPlaced(DefinedError):
    """PutLabware did not put the plate down in the nest."""

    identifier = "LabwareNotPlaced"


class UnknownPointOfInterest(DefinedError):
    identifier = "UnknownPointOfInterest"


class NavigationFailed(DefinedError):
    identifier = "NavigationFailed"


class DockingFailed(DefinedError):
    identifier = "DockingFailed"


class UndockingFailed(DefinedError):
    identifier = "UndockingFailed"


class RobotDocked(DefinedError):
    """The robot is on its dock; undock first."""

    identifier = "RobotDocked"


class RobotBusy(DefinedError):
    """Another motion or transfer runs; motion commands are refused, not queued."""

    identifier = "RobotBusy"


class MotionStopped(DefinedError):
    """The motion was ended early by StopMotion."""

    identifier = "MotionStopped"


class UnknownLabware(DefinedError):
    """The robot knows no plate of this id (never handled, or lost after a failed transfer)."""

    identifier = "UnknownLabware"


class ParameterRejected(LabwareTransferError, ValueError):
    """A parameter value was refused (by the server's validation, or by the client before sending)."""

    def __init__(self, message: str, *, command: str = "", step: str = "", parameter: str = "") -> None:
        self.parameter = parameter
        super().__init__(message, command=command, step=step)


class UndefinedServerError(LabwareTransferError):
    """The server failed with an error its features do not define (an undefined execution error,
    or a SiLA framework error such as an execution it no longer knows)."""


class StepTimeout(LabwareTransferError, TimeoutError):
    """A step's commands were not all finished within the client's step timeout."""


class ServerUnreachable(LabwareTransferError, ConnectionError):
    """No answer from a server: not running, wrong address, or TLS refused (wrong CA)."""


DEFINED_ERRORS: dict[str, type[DefinedError]] = {
    error.identifier: error
    for error in (
        InvalidCommandSequence,
        LabwareNotPicked,
        LabwareNotPlaced,
        UnknownPointOfInterest,
        NavigationFailed,
        DockingFailed,
        UndockingFailed,
        RobotDocked,
        RobotBusy,
        MotionStopped,
        UnknownLabware,
    )
}


def translate(error: Exception, *, command: str, step: str = "") -> Exception:
    """The typed client exception for an error sila2 raised; other exceptions come back unchanged.

    Raise the result `from error`, so the sila2 original stays attached as the cause.
    """
    if isinstance(error, LabwareTransferError):
        return error
    step = step or command
    if isinstance(error, DefinedExecutionError):
        defined = DEFINED_ERRORS.get(error.identifier, DefinedError)
        return defined(error.message, command=command, step=step, identifier=error.identifier)
    if isinstance(error, ValidationError):
        parameter = _parameter_name(error)
        return ParameterRejected(error.message, command=command, step=step, parameter=parameter)
    if isinstance(error, UndefinedExecutionError):
        return UndefinedServerError(error.message, command=command, step=step)
    if isinstance(error, FrameworkError):
        return UndefinedServerError(f"{type(error).__name__}: {error}", command=command, step=step)
    if isinstance(error, SilaConnectionError):
        return ServerUnreachable(str(error), command=command, step=step)
    return error


def _parameter_name(error: ValidationError) -> str:
    """The refused parameter's identifier, "" when unknown.

    sila2's client gives the parameter's node when the server named it, and None when its own
    constraint check refused the value before sending (the message then names the constraint).
    """
    node = error.parameter_fully_qualified_identifier
    identifier = getattr(node, "fully_qualified_identifier", node)
    return str(identifier).rsplit("/", 1)[-1] if identifier else ""
