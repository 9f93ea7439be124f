"""`LabwareTransferClient` against a real stack: typed errors, progress records, the robot's commands.

The tests share one stack (default world: plate_001 in station_a/1, the robot docked) and run in
file order: refusals first (nothing moves), then a transfer through internal position 2, then a
drive stopped from another thread (which leaves the robot between points of interest).
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from itertools import groupby

import pytest
from sila2.client import SilaClient
from sila2.framework import DefinedExecutionError

from labware_model.holders import Nest
from sila_labware.client import (
    DefinedError,
    InvalidCommandSequence,
    LabwareTransferClient,
    LabwareTransferError,
    MotionStopped,
    ParameterRejected,
    ServerUnreachable,
    StepProgress,
    UnknownLabware,
)
from sila_labware.client.sequence import PREPARE_DESTINATION, TRANSFER_STEPS
from sila_labware.client.steps import Command, run_step
from sila_labware.deployment.clients import transfer_client
from sila_labware.deployment.stack import Deployment
from tests.helpers.sila_stack import free_port_base, start_stack
from tests.helpers.sim_parameters import set_node_parameter

PLATE = "plate_001"


@pytest.fixture(scope="module")
def stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Deployment]:
    deployment = start_stack(tmp_path_factory.mktemp("client"), insecure=True)
    yield deployment
    deployment.stop()


@pytest.fixture(scope="module")
def client(stack: Deployment) -> Iterator[LabwareTransferClient]:
    with transfer_client(stack) as connected:
        yield connected


def robot_state(stack: Deployment) -> str:
    assert stack.link is not None
    return stack.link.robot_status().state


def test_the_client_learns_the_stations_from_their_servers(client: LabwareTransferClient) -> None:
    assert client.stations == ("station_a", "station_b")
    assert [(p.position, p.sub_positions) for p in client.handover_positions()] == [
        ("station_a", 2),
        ("station_b", 2),
    ]
    assert client.internal_positions() == 2
    assert "lab_centre" in client.points_of_interest()


def test_getlabware_without_prepare_is_an_invalid_command_sequence(stack: Deployment) -> None:
    robot = stack.robot_server()
    with SilaClient(robot.host, robot.port, insecure=True) as sila:
        manipulator = sila.LabwareTransferManipulatorController
        get = Command(
            "Robot.GetLabware",
            lambda: manipulator.GetLabware(HandoverPosition=("station_a", 1), IntermediateActions=[]),
        )
        with pytest.raises(InvalidCommandSequence) as caught:
            run_step("Robot.GetLabware", [get])
    error = caught.value
    assert isinstance(error, DefinedError) and isinstance(error, LabwareTransferError)
    assert (error.identifier, error.command, error.step) == (
        "InvalidCommandSequence",
        "Robot.GetLabware",
        "Robot.GetLabware",
    )
    assert "GetLabware needs PrepareForInput first; the robot is idle" == error.message
    assert isinstance(error.__cause__, DefinedExecutionError)  # sila2's original stays attached


def test_placing_from_an_empty_slot_into_a_full_nest_is_refused_by_both_before_any_motion(
    stack: Deployment, client: LabwareTransferClient
) -> None:
    """Both Prepare commands are sent and both refuse; the first one's error is raised."""
    with pytest.raises(InvalidCommandSequence) as caught:
        client.place(("station_a", 1), internal_position=1)
    error = caught.value
    assert (error.command, error.step) == ("station_a.PrepareForInput", PREPARE_DESTINATION)
    assert "nest station_a/1 is occupied" in error.message
    assert str(error).startswith(f"station_a.PrepareForInput (step {PREPARE_DESTINATION}): ")
    assert robot_state(stack) == "docked"


def test_an_unknown_plate_is_unknown_labware(client: LabwareTransferClient) -> None:
    with pytest.raises(UnknownLabware) as caught:
        client.locate("plate_999")
    assert caught.value.command == "Robot.LocateLabware"
    assert "plate_999" in caught.value.message


def test_bad_parameters_are_rejected_by_the_server_or_before_sending(
    stack: Deployment, client: LabwareTransferClient
) -> None:
    robot = stack.robot_server()
    with SilaClient(robot.host, robot.port, insecure=True) as sila:
        manipulator = sila.LabwareTransferManipulatorController
        beyond = Command(
            "Robot.PrepareForOutput",
            lambda: manipulator.PrepareForOutput(HandoverPosition=("station_b", 1), InternalPosition=3),
        )
        with pytest.raises(ParameterRejected, match="beyond this device's 2 internal positions") as by_server:
            run_step(PREPARE_DESTINATION, [beyond])
    assert by_server.value.parameter == "InternalPosition"
    with pytest.raises(ParameterRejected, match="MinimalLength"):
        client.locate("")  # the feature constrains ids to at least one character; sila2 checks first
    with pytest.raises(ParameterRejected, match="no connected station serves 'station_z'"):
        client.transfer(("station_a", 1), ("station_z", 1))
    with pytest.raises(ParameterRejected, match="is not a whole number from 1"):
        client.pick(("station_a", 0))
    assert robot_state(stack) == "docked"


def test_no_server_is_server_unreachable() -> None:
    with pytest.raises(ServerUnreachable, match="no SiLA server answers"):
        LabwareTransferClient(("127.0.0.1", free_port_base(1)), [], insecure=True)


def test_a_transfer_reports_every_step_with_progress_that_never_goes_down(
    stack: Deployment, client: LabwareTransferClient
) -> None:
    records: list[StepProgress] = []
    client.transfer(
        ("station_a", 1), ("station_b", 1), labware_id=PLATE, internal_position=2, on_progress=records.append
    )

    by_step = [(step, list(group)) for step, group in groupby(records, key=lambda record: record.step)]
    assert [step for step, _ in by_step] == list(TRANSFER_STEPS)
    for step, step_records in by_step:
        first, last = step_records[0], step_records[-1]
        assert (first.progress, first.elapsed_s, first.done) == (0.0, 0.0, False), step
        assert (last.progress, last.done) == (1.0, True), step
        assert not any(record.done for record in step_records[:-1]), step
        progresses = [record.progress for record in step_records]
        assert progresses == sorted(progresses) and all(0.0 <= p <= 1.0 for p in progresses), step
        elapsed = [record.elapsed_s for record in step_records]
        assert elapsed == sorted(elapsed), step
    get_labware = dict(by_step)["Robot.GetLabware"]
    assert any(0.0 < record.progress < 1.0 and record.remaining_s is not None for record in get_labware)

    assert stack.link is not None
    assert stack.link.check_placement(PLATE, Nest("station_b", 1)).in_nest
    location = client.locate(PLATE)
    assert (location.aboard, location.location) == (False, Nest("station_b", 1))
    assert client.onboard_labware() == []


def test_stop_from_another_thread_ends_a_drive_with_motion_stopped(
    stack: Deployment, client: LabwareTransferClient
) -> None:
    """The drive runs at real time (unpaced, a loaded machine may finish it before the stop)."""
    under_way = threading.Event()
    outcome: list[BaseException] = []

    def drive() -> None:
        try:
            client.drive_to("lab_centre", on_progress=lambda record: record.progress > 0 and under_way.set())
        except BaseException as error:  # noqa: BLE001 - handed to the test thread
            outcome.append(error)

    assert stack.runtime is not None
    set_node_parameter(stack.runtime, "realtime_factor_cap", 1.0)
    try:
        driver = threading.Thread(target=drive)
        driver.start()
        assert under_way.wait(30), f"the drive never reported progress: {outcome}"
        client.stop()
        driver.join(30)
    finally:
        set_node_parameter(stack.runtime, "realtime_factor_cap", 0.0)
    assert len(outcome) == 1 and isinstance(outcome[0], MotionStopped), outcome
    assert outcome[0].command == "Robot.DriveToPointOfInterest"
