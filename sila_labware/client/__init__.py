"""A client for people who build on the robot: the standard labware transfer as method calls.

    from sila_labware.client import LabwareTransferClient

    ca = open("sila-labware-ca.pem", "rb").read()
    with LabwareTransferClient(("127.0.0.1", 50052), [("127.0.0.1", 50053), ("127.0.0.1", 50054)],
                               root_certs=ca) as robot:
        robot.transfer(("station_a", 1), ("station_b", 1), labware_id="plate_001")
        robot.dock()

Depends only on sila2's client (no ROS, nothing of the servers), so it runs wherever the servers
can be reached. `transfer_client` holds the class, `sequence` the standard's steps and commands,
`steps` how one step is run and its progress record, `errors` the typed exceptions, `records` the
values passed in and out, `console` command-line options and a progress line for scripts.
"""

from sila_labware.client.errors import (
    DefinedError,
    DockingFailed,
    InvalidCommandSequence,
    LabwareNotPicked,
    LabwareNotPlaced,
    LabwareTransferError,
    MotionStopped,
    NavigationFailed,
    ParameterRejected,
    RobotBusy,
    RobotDocked,
    ServerUnreachable,
    StepTimeout,
    UndefinedServerError,
    UndockingFailed,
    UnknownLabware,
    UnknownPointOfInterest,
)
from sila_labware.client.records import HandoverPosition, LabwareLocation, OnboardLabware
from sila_labware.client.sequence import PICK_STEPS, PLACE_STEPS, TRANSFER_STEPS
from sila_labware.client.steps import StepProgress
from sila_labware.client.transfer_client import LabwareTransferClient

__all__ = [
    "PICK_STEPS",
    "PLACE_STEPS",
    "TRANSFER_STEPS",
    "DefinedError",
    "DockingFailed",
    "HandoverPosition",
    "InvalidCommandSequence",
    "LabwareLocation",
    "LabwareNotPicked",
    "LabwareNotPlaced",
    "LabwareTransferClient",
    "LabwareTransferError",
    "MotionStopped",
    "NavigationFailed",
    "OnboardLabware",
    "ParameterRejected",
    "RobotBusy",
    "RobotDocked",
    "ServerUnreachable",
    "StepProgress",
    "StepTimeout",
    "UndefinedServerError",
    "UndockingFailed",
    "UnknownLabware",
    "UnknownPointOfInterest",
]
