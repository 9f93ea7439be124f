"""Errors of the robot logic, free of SiLA and ROS; the feature implementations translate them.

`CommandSequenceError` becomes the standard's defined error InvalidCommandSequence;
`ParameterError` becomes a SiLA validation error naming the parameter;
`TransferFailed` and `MotionFailed` become the command's own defined error for the robot side's code.
"""

from __future__ import annotations


class CommandSequenceError(Exception):
    """A command arrived in an order the labware transfer protocol does not allow."""


class ParameterError(ValueError):
    """A parameter value is outside what this device offers; `parameter` is its SiLA identifier."""

    def __init__(self, parameter: str, message: str) -> None:
        super().__init__(message)
        self.parameter = parameter
        self.message = message


class TransferFailed(Exception):
    """GetLabware/PutLabware did not move the plate; `error_code` is the robot side's code."""

    def __init__(self, error_code: str, message: str) -> None:
        super().__init__(message)
        self.error_code = error_code
        self.message = message


class MotionFailed(Exception):
    """A base motion (dock, undock, drive) failed; `error_code` is the robot side's code."""

    def __init__(self, error_code: str, message: str) -> None:
        super().__init__(message)
        self.error_code = error_code
        self.message = message
