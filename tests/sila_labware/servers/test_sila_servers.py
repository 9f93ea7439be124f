"""Real sila2 clients over TLS on 127.0.0.1 against the robot and station servers, backed by the
real simulation node and sequencer: properties, command order, parameter errors, robustness."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from sila2.client import SilaClient
from sila2.framework import DefinedExecutionError, ValidationError

from sila_labware.deployment.stack import Deployment
from tests.helpers.sila_stack import client_for, start_stack
from tests.helpers.sim_parameters import set_node_parameter

MANIPULATOR = "org.silastandard/instruments.labware.manipulation/LabwareTransferManipulatorController/v1"
SITE = "org.silastandard/instruments.labware.manipulation/LabwareTransferSiteController/v1"


@pytest.fixture(scope="module")
def stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Deployment]:
    deployment = start_stack(tmp_path_factory.mktemp("sila_servers"), discovery=True)
    yield deployment
    started = time.monotonic()
    deployment.stop()
    assert time.monotonic() - started < 5.0, "stopping everything must take under 5 s"
    assert not any(child.running for child in deployment.children.children)


@pytest.fixture(scope="module")
def robot(stack: Deployment) -> SilaClient:
    return client_for(stack, stack.robot_server())


@pytest.fixture(scope="module")
def station_a(stack: Deployment) -> SilaClient:
    return client_for(stack, stack.station_server("station_a"))


@pytest.fixture(scope="module")
def station_b(stack: Deployment) -> SilaClient:
    return client_for(stack, stack.station_server("station_b"))


def finish(start: Callable[[], Any]) -> Any:
    """Run an observable command to its end and return its responses (raising its error)."""
    instance = start()
    deadline = time.monotonic() + 60.0
    while not instance.done:
        assert time.monotonic() < deadline, "command did not finish within 60 s"
        time.sleep(0.05)
    return instance.get_responses()


def expect_defined(identifier: str, start: Callable[[], Any], match: str) -> DefinedExecutionError:
    with pytest.raises(DefinedExecutionError) as caught:
        finish(start)
    assert caught.value.identifier == identifier
    assert match in caught.value.message, caught.value.message
    return caught.value


def expect_invalid(parameter: str, start: Callable[[], Any], match: str) -> None:
    with pytest.raises(ValidationError) as caught:
        finish(start)
    assert match in caught.value.message, caught.value.message
    named = caught.value.parameter_fully_qualified_identifier  # the client resolves it to the parameter
    assert named is not None, "the server must name the parameter"
    assert str(named.fully_qualified_identifier).endswith(f"/Parameter/{parameter}")


def test_properties_describe_the_workcell(
    stack: Deployment, robot: SilaClient, station_a: SilaClient
) -> None:
    manipulator = robot.LabwareTransferManipulatorController
    positions = [(item.Position, item.SubPosition) for item in manipulator.AvailableHandoverPositions.get()]
    assert positions == [(station.name, station.sub_positions) for station in stack.workcell.stations]
    assert positions == [("station_a", 2), ("station_b", 2)]
    assert manipulator.NumberOfInternalPositions.get() == 2
    assert manipulator.AvailableIntermediateActions.get() == []
    site = station_a.LabwareTransferSiteController
    assert [(item.Position, item.SubPosition) for item in site.AvailableHandoverPositions.get()] == [
        ("station_a", 2)
    ]
    assert site.NumberOfInternalPositions.get() == 1
    assert robot.MobileRobotController.RobotState.get() == "Docked"
    assert robot.MobileRobotController.OnboardLabware.get() == []
    assert "station_a_work" in robot.MobileRobotController.PointsOfInterest.get()
    pose = robot.MobileRobotController.RobotPose.get()
    assert (round(pose.X, 2), round(pose.Y, 2)) == (-1.5, -1.0)  # the dock pose of the world file


def test_servers_use_tls_and_are_discoverable(stack: Deployment) -> None:
    served = stack.robot_server()
    ca = stack.ca_file.read_bytes()
    assert ca.count(b"BEGIN CERTIFICATE") == 1  # one CA for every server of the deployment
    with pytest.raises(Exception):  # noqa: B017 - any failure to talk plain text to a TLS server
        SilaClient(served.host, served.port, insecure=True).SiLAService.ServerName.get()
    found = SilaClient.discover(server_uuid=served.server.server_uuid, timeout=10, root_certs=ca)
    assert found.SiLAService.ServerName.get() == "TIAGo Labware Robot (default lab)"


def test_out_of_order_commands_are_invalid_command_sequence(
    robot: SilaClient, station_a: SilaClient, station_b: SilaClient
) -> None:
    manipulator = robot.LabwareTransferManipulatorController
    a = station_a.LabwareTransferSiteController
    b = station_b.LabwareTransferSiteController
    where_a, where_b = ("station_a", 1), ("station_b", 1)
    error = expect_defined(
        "InvalidCommandSequence",
        lambda: manipulator.GetLabware(HandoverPosition=where_a, IntermediateActions=[]),
        "GetLabware needs PrepareForInput first",
    )
    assert str(error.fully_qualified_identifier).startswith(MANIPULATOR)
    expect_defined(
        "InvalidCommandSequence",
        lambda: manipulator.PutLabware(HandoverPosition=where_b, IntermediateActions=[]),
        "PutLabware needs PrepareForOutput first",
    )
    expect_defined(
        "InvalidCommandSequence",
        lambda: manipulator.PrepareForOutput(HandoverPosition=where_b, InternalPosition=1),
        "internal position 1 holds no labware",
    )
    error = expect_defined(
        "InvalidCommandSequence",
        lambda: a.LabwareRemoved(HandoverPosition=where_a),
        "needs PrepareForOutput first",
    )
    assert str(error.fully_qualified_identifier).startswith(SITE)
    expect_defined(
        "InvalidCommandSequence",
        lambda: b.LabwareDelivered(HandoverPosition=where_b),
        "needs PrepareForInput first",
    )
    expect_defined(
        "InvalidCommandSequence",
        lambda: a.PrepareForInput(
            HandoverPosition=where_a, InternalPosition=1, LabwareType="", LabwareUniqueID=""
        ),
        "nest station_a/1 is occupied",
    )
    expect_defined(
        "InvalidCommandSequence",
        lambda: b.PrepareForOutput(HandoverPosition=where_b, InternalPosition=1),
        "nest station_b/1 is empty",
    )
    # A station prepared for output refuses a second prepare and the wrong completion.
    finish(lambda: a.PrepareForOutput(HandoverPosition=where_a, InternalPosition=1))
    expect_defined(
        "InvalidCommandSequence",
        lambda: a.PrepareForOutput(HandoverPosition=where_a, InternalPosition=1),
        "already prepared for output; LabwareRemoved must come first",
    )
    expect_defined(
        "InvalidCommandSequence",
        lambda: a.LabwareDelivered(HandoverPosition=where_a),
        "needs PrepareForInput first",
    )
    # The plate never left: LabwareRemoved is refused on the sensor's word, the nest stays prepared.
    expect_defined(
        "InvalidCommandSequence", lambda: a.LabwareRemoved(HandoverPosition=where_a), "still sees a plate"
    )


def test_bad_inputs_are_named_and_change_nothing(robot: SilaClient, station_a: SilaClient) -> None:
    manipulator = robot.LabwareTransferManipulatorController
    site = station_a.LabwareTransferSiteController

    def prepare_input(
        position: tuple[str, int], internal: int = 1, labware_type: str = ""
    ) -> Callable[[], Any]:
        return lambda: manipulator.PrepareForInput(
            HandoverPosition=position,
            InternalPosition=internal,
            LabwareType=labware_type,
            LabwareUniqueID="p",
        )

    expect_invalid("HandoverPosition", prepare_input(("oven", 1)), "unknown handover position 'oven'")
    expect_invalid("HandoverPosition", prepare_input(("station_a", 3)), "SubPosition 3 is beyond")
    expect_invalid(
        "InternalPosition", prepare_input(("station_a", 1), internal=3), "InternalPosition 3 is beyond"
    )
    expect_invalid("LabwareType", prepare_input(("station_a", 1), labware_type="x" * 300), "at most 255")
    with pytest.raises(ValidationError):  # PositionIndex >= 1, enforced by the sila2 library itself
        finish(prepare_input(("station_a", 1), internal=0))
    expect_invalid(
        "IntermediateActions",
        lambda: manipulator.GetLabware(HandoverPosition=("station_a", 1), IntermediateActions=["shake"]),
        "unknown intermediate action 'shake'",
    )
    expect_invalid(
        "HandoverPosition",
        lambda: site.PrepareForOutput(HandoverPosition=("station_b", 1), InternalPosition=1),
        "unknown handover position 'station_b'",
    )
    expect_invalid(
        "InternalPosition",
        lambda: site.PrepareForOutput(HandoverPosition=("station_a", 1), InternalPosition=2),
        "1 internal positions",
    )
    # The server is still up and nothing moved or was recorded.
    assert manipulator.NumberOfInternalPositions.get() == 2
    assert robot.MobileRobotController.RobotState.get() == "Docked"
    # the inventory knows the plate its sensors see, by its label, and no name the bad inputs used
    locations = robot.LabwareInventory.LabwareLocations.get()
    assert [(item.LabwareUniqueID, item.Aboard, item.Position, item.Index) for item in locations] == [
        ("plate_001", False, "station_a", 1)
    ]
    with pytest.raises(DefinedExecutionError) as caught:
        robot.LabwareInventory.LocateLabware(LabwareUniqueID="p")
    assert caught.value.identifier == "UnknownLabware"


def test_motion_commands_map_robot_side_errors(robot: SilaClient) -> None:
    motion = robot.MobileRobotController
    expect_defined(
        "RobotDocked",
        lambda: motion.DriveToPointOfInterest(PointOfInterest="station_a_work"),
        "undock before driving",
    )
    with pytest.raises(ValidationError, match="no point of interest 'nowhere'"):
        motion.DriveToPointOfInterest(PointOfInterest="nowhere")  # refused on the initiating call
    finish(lambda: motion.Dock())  # already docked: succeeds at once
    assert motion.RobotState.get() == "Docked"


def occlude_marker(stack: Deployment, station: str) -> None:
    """Fault injection the sim node offers for tests: hide a station's marker from the camera."""
    set_node_parameter(stack.runtime, "fault.occlude_marker", station)


def test_failed_get_is_labware_not_picked_and_inventory_stays_true(
    stack: Deployment, robot: SilaClient, station_a: SilaClient
) -> None:
    """station_a/1 was left prepared for output by the command-order test; the plate is there."""
    manipulator = robot.LabwareTransferManipulatorController
    where = ("station_a", 1)
    occlude_marker(stack, "station_a")
    try:
        finish(
            lambda: manipulator.PrepareForInput(
                HandoverPosition=where, InternalPosition=1, LabwareType="", LabwareUniqueID="plate_001"
            )
        )
        assert robot.MobileRobotController.CurrentPointOfInterest.get() == "station_a_work"
        with pytest.raises(DefinedExecutionError) as caught:
            finish(lambda: manipulator.GetLabware(HandoverPosition=where, IntermediateActions=[]))
        assert caught.value.identifier == "LabwareNotPicked"
        assert "MARKER_NOT_FOUND" in caught.value.message, caught.value.message
    finally:
        occlude_marker(stack, "")
    location = robot.LabwareInventory.LocateLabware(LabwareUniqueID="plate_001").Location
    assert (location.Aboard, location.Position, location.Index) == (False, "station_a", 1)
    assert robot.MobileRobotController.OnboardLabware.get() == []
    expect_defined(  # the failed step ended the handover: prepare again before another GetLabware
        "InvalidCommandSequence",
        lambda: manipulator.GetLabware(HandoverPosition=where, IntermediateActions=[]),
        "needs PrepareForInput first",
    )


def test_stop_motion_cancels_a_drive_through_the_whole_stack(stack: Deployment, robot: SilaClient) -> None:
    """Runs last in this module: it leaves the robot undocked."""
    motion = robot.MobileRobotController
    finish(lambda: motion.Undock())
    assert motion.RobotState.get() == "Idle"
    # At real time the 2.4 m drive takes seconds of wall time, so StopMotion surely lands mid-drive
    # (unpaced, a loaded machine may finish it before the stop arrives).
    set_node_parameter(stack.runtime, "realtime_factor_cap", 1.0)
    try:
        drive = motion.DriveToPointOfInterest(PointOfInterest="lab_centre")
        stop_mid_drive(motion, drive)
    finally:
        set_node_parameter(stack.runtime, "realtime_factor_cap", 0.0)
    with pytest.raises(DefinedExecutionError) as caught:
        drive.get_responses()
    assert caught.value.identifier == "MotionStopped"
    assert motion.CurrentPointOfInterest.get() != "lab_centre"


def stop_mid_drive(motion: Any, drive: Any) -> None:
    """Wait for the drive's first progress, check its estimate, stop it, wait for its end."""
    deadline = time.monotonic() + 30.0
    while not (drive.progress or 0.0) > 0.0:
        assert time.monotonic() < deadline and not drive.done, "the drive never reported progress"
        time.sleep(0.05)
    assert drive.estimated_remaining_time is not None and drive.estimated_remaining_time.total_seconds() > 0
    motion.StopMotion()
    while not drive.done:
        assert time.monotonic() < deadline, "the drive did not end after StopMotion"
        time.sleep(0.05)
