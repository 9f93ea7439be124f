"""Errors of the robot logic, free of SiLA and ROS; the feature implementations translate them.

`CommandSequenceError` becomes the standard's defined error InvalidCommandSequence;
`ParameterError` becomes a SiLA validation error naming the parameter; `TransferFailed` becomes
LabwareNotPicked or LabwareNotPlaced, `MotionFailed` the MobileRobotController error for its code
(in a labware transfer command: InvalidCommandSequence from Prepare*, whose drive left nothing
prepared; LabwareNotPicked/LabwareNotPlaced from GetLabware/PutLabware).
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


class RobotSideFailure(Exception):
    """A robot goal ended without success; `error_code` is the robot side's code (labware_interfaces
    ErrorCodes, or the bridge's error name when no answer came)."""

    def __init__(self, error_code: str, message: str) -> None:
        super().__init__(message)
        self.error_code = error_code
        self.message = message


class TransferFailed(RobotSideFailure):
    """GetLabware/PutLabware did not move the plate."""


class MotionFailed(RobotSideFailure):
    """A base motion (dock, undock, drive) failed."""
