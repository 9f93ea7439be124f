"""Bad parameters of observable commands are refused on the initiating call, as SiLA asks.

Before: sila2 answered the initiation with an execution UUID, and our checks failed the
execution afterwards (running -> finishedWithError). Now a validation error naming the parameter
answers the initiating call itself, and no execution is created (the servers keep no command
manager for it). Real servers over gRPC, a real sila2 client, the real robot side.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest
from sila2.client import SilaClient
from sila2.framework import ValidationError

from sila_labware.deployment.stack import Deployment
from tests.helpers.sila_stack import client_for, start_stack
from tests.helpers.transfer_steps import finish

MANIPULATOR = "org.silastandard/instruments.labware.manipulation/LabwareTransferManipulatorController/v1"
SITE = "org.silastandard/instruments.labware.manipulation/LabwareTransferSiteController/v1"
MOBILE = "org.labwaretransfer/robotics.mobile/MobileRobotController/v1"
A1 = {"Position": "station_a", "SubPosition": 1}


@pytest.fixture(scope="module")
def stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Deployment]:
    deployment = start_stack(tmp_path_factory.mktemp("initiation"), insecure=True)
    yield deployment
    deployment.stop()


@pytest.fixture(scope="module")
def robot(stack: Deployment) -> SilaClient:
    return client_for(stack, stack.robot_server())


@pytest.fixture(scope="module")
def station_a(stack: Deployment) -> SilaClient:
    return client_for(stack, stack.station_server("station_a"))


def named_parameter(error: ValidationError) -> str:
    """The fully qualified identifier of the parameter a validation error names (sila2's client
    gives the parameter node)."""
    return str(error.parameter_fully_qualified_identifier.fully_qualified_identifier)


def executions(stack: Deployment) -> int:
    """Observable command executions the servers hold (sila2 keeps one manager per execution)."""
    servers = [stack.robot_server().server, *(s.server for s in stack.servers if s.role == "station")]
    return sum(
        len(managers)
        for server in servers
        for servicer in server.feature_servicers.values()
        for managers in getattr(servicer, "observable_command_managers", {}).values()
    )


def robot_calls(robot: SilaClient) -> dict[str, tuple[Callable[[], Any], str]]:
    manipulator, mobile = robot.LabwareTransferManipulatorController, robot.MobileRobotController

    def prepare_for_input(handover: dict[str, Any] = A1, internal: int = 1, kind: str = "", plate: str = ""):
        return lambda: manipulator.PrepareForInput(
            HandoverPosition=handover, InternalPosition=internal, LabwareType=kind, LabwareUniqueID=plate
        )

    return {
        "unknown handover position": (
            prepare_for_input({"Position": "oven", "SubPosition": 1}),
            f"{MANIPULATOR}/Command/PrepareForInput/Parameter/HandoverPosition",
        ),
        "sub-position beyond the station's nests": (
            prepare_for_input({"Position": "station_a", "SubPosition": 3}),
            f"{MANIPULATOR}/Command/PrepareForInput/Parameter/HandoverPosition",
        ),
        "internal position beyond the hotel": (
            lambda: manipulator.PrepareForOutput(HandoverPosition=A1, InternalPosition=3),
            f"{MANIPULATOR}/Command/PrepareForOutput/Parameter/InternalPosition",
        ),
        "labware id over 255 characters": (
            prepare_for_input(plate="p" * 256),
            f"{MANIPULATOR}/Command/PrepareForInput/Parameter/LabwareUniqueID",
        ),
        "labware id with a control character": (
            prepare_for_input(plate="plate\x07"),
            f"{MANIPULATOR}/Command/PrepareForInput/Parameter/LabwareUniqueID",
        ),
        "labware type with a control character": (
            prepare_for_input(kind="sbs\n96"),
            f"{MANIPULATOR}/Command/PrepareForInput/Parameter/LabwareType",
        ),
        "unknown intermediate action": (
            lambda: manipulator.GetLabware(
                HandoverPosition=A1, IntermediateActions=["org.example/x/Shaker/v1/Command/Shake"]
            ),
            f"{MANIPULATOR}/Command/GetLabware/Parameter/IntermediateActions",
        ),
        "put at an unknown station": (
            lambda: manipulator.PutLabware(
                HandoverPosition={"Position": "oven", "SubPosition": 1}, IntermediateActions=[]
            ),
            f"{MANIPULATOR}/Command/PutLabware/Parameter/HandoverPosition",
        ),
        "unknown point of interest": (
            lambda: mobile.DriveToPointOfInterest(PointOfInterest="attic"),
            f"{MOBILE}/Command/DriveToPointOfInterest/Parameter/PointOfInterest",
        ),
    }


@pytest.mark.parametrize(
    "case",
    [
        "unknown handover position",
        "sub-position beyond the station's nests",
        "internal position beyond the hotel",
        "labware id over 255 characters",
        "labware id with a control character",
        "labware type with a control character",
        "unknown intermediate action",
        "put at an unknown station",
        "unknown point of interest",
    ],
)
def test_the_robot_refuses_a_bad_parameter_on_the_initiating_call(
    stack: Deployment, robot: SilaClient, case: str
) -> None:
    call, parameter = robot_calls(robot)[case]
    before = executions(stack)
    with pytest.raises(ValidationError) as refused:
        call()  # the initiation itself raises: no execution UUID comes back
    assert named_parameter(refused.value) == parameter
    assert executions(stack) == before, "a refused initiation must not create an execution"


@pytest.mark.parametrize(
    ("call", "parameter"),
    [
        (
            lambda site: site.PrepareForInput(
                HandoverPosition={"Position": "station_b", "SubPosition": 1},
                InternalPosition=1,
                LabwareType="",
                LabwareUniqueID="",
            ),
            "PrepareForInput/Parameter/HandoverPosition",
        ),
        (
            lambda site: site.PrepareForOutput(HandoverPosition=A1, InternalPosition=2),
            "PrepareForOutput/Parameter/InternalPosition",
        ),
        (
            lambda site: site.LabwareDelivered(HandoverPosition={"Position": "station_a", "SubPosition": 9}),
            "LabwareDelivered/Parameter/HandoverPosition",
        ),
    ],
)
def test_a_station_refuses_a_bad_parameter_on_the_initiating_call(
    stack: Deployment, station_a: SilaClient, call: Callable[[Any], Any], parameter: str
) -> None:
    before = executions(stack)
    with pytest.raises(ValidationError) as refused:
        call(station_a.LabwareTransferSiteController)
    assert named_parameter(refused.value) == f"{SITE}/Command/{parameter}"
    assert executions(stack) == before


def test_a_valid_command_still_starts_and_runs(stack: Deployment, robot: SilaClient) -> None:
    """The checks let good calls through to sila2 unchanged: Undock runs, Dock brings it back."""
    mobile = robot.MobileRobotController
    finish(mobile.Undock())
    assert stack.link is not None and not stack.link.robot_status().docked
    finish(mobile.Dock())
    assert stack.link.robot_status().docked
