"""Two SiLA clients (separate SilaClient objects, separate channels) command one robot at once.

Policy under test: refuse by sequence, for clients that do not lock the robot (LockController,
when a client uses it, refuses the other clients' calls outright). The robot runs one thing at a time
(`ManipulatorSequence`); a command arriving while a motion or transfer runs, or while another
client's preparation is pending, gets a defined error that says what the robot is busy with:
RobotBusy for MobileRobotController motions, InvalidCommandSequence for the labware-transfer
commands. The refusal happens in the SiLA server before any ROS goal is sent, so the robot side
never sees a second motion (checked in the sim node's one-line-per-goal log: no BUSY there, and
goal spans never overlap). Afterwards station and robot state agree and a transfer succeeds.
"""

from __future__ import annotations

import re
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from sila2.client import SilaClient
from sila2.framework import DefinedExecutionError

from tests.helpers.sila_stack import client_for, start_stack
from tests.helpers.sim_parameters import set_node_parameter
from tests.helpers.transfer_steps import Cell, finish

PLATE = "plate_001"
A1, B1 = ("station_a", 1), ("station_b", 1)
GOAL_LINE = re.compile(r"INFO tiago_skills\.action_servers: (/\w+) (\w+): sim ([\d.]+) \.\. ([\d.]+) s")


@pytest.fixture(scope="module")
def cell(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cell]:
    deployment = start_stack(tmp_path_factory.mktemp("concurrency"), insecure=True)
    yield Cell(deployment)
    deployment.stop()


@pytest.fixture(scope="module")
def second(cell: Cell) -> SilaClient:
    """A second client of the robot server: its own SilaClient and gRPC channel."""
    return client_for(cell.deployment, cell.deployment.robot_server())


def robot_goals(cell: Cell) -> list[tuple[str, str, float, float]]:
    """(action, outcome, sim start, sim end) for every goal the sim node ran, from its log."""
    assert cell.deployment.options.log_dir is not None
    text = (cell.deployment.options.log_dir / "sim_node.log").read_text(errors="replace")
    return [(m[1], m[2], float(m[3]), float(m[4])) for m in GOAL_LINE.finditer(text)]


def assert_one_motion_at_a_time(goals: list[tuple[str, str, float, float]]) -> None:
    assert all(outcome != "BUSY" for _, outcome, _, _ in goals), goals
    spans = sorted((start, end) for _, _, start, end in goals)
    for (_, end), (next_start, _) in zip(spans, spans[1:], strict=False):
        assert next_start >= end - 1e-6, f"two goals overlapped: {spans}"


def refused(identifier: str, start: Callable[[], Any], match: str) -> str:
    """Run a command that must be refused; return the message the caller got."""
    with pytest.raises(DefinedExecutionError) as caught:
        finish(start(), timeout_s=30.0)
    assert caught.value.identifier == identifier, caught.value
    assert match in caught.value.message, caught.value.message
    return caught.value.message


def wait_progress(instance: Any) -> None:
    deadline = time.monotonic() + 30.0
    while not (instance.progress or 0.0) > 0.0:
        assert time.monotonic() < deadline and not instance.done, "the command never reported progress"
        time.sleep(0.02)


def test_second_client_is_refused_while_the_first_drives(cell: Cell, second: SilaClient) -> None:
    first_motion = cell.robot.MobileRobotController
    second_motion = second.MobileRobotController
    finish(first_motion.Undock())
    goals_before = len(robot_goals(cell))
    assert cell.deployment.runtime is not None
    # At real time the drive lasts seconds of wall time, so every refusal below lands mid-drive.
    set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 1.0)
    try:
        drive = first_motion.DriveToPointOfInterest(PointOfInterest="station_a_work")
        wait_progress(drive)
        messages = [
            refused(
                "RobotBusy",
                lambda: second_motion.DriveToPointOfInterest(PointOfInterest="station_b_work"),
                "DriveToPointOfInterest refused: the robot is busy moving",
            ),
            refused("RobotBusy", second_motion.Dock, "Dock refused: the robot is busy moving"),
            refused(
                "InvalidCommandSequence",
                lambda: second.LabwareTransferManipulatorController.PrepareForInput(
                    HandoverPosition=A1, InternalPosition=1, LabwareType="", LabwareUniqueID=PLATE
                ),
                "PrepareForInput refused: the robot is busy moving",
            ),
            refused(
                "InvalidCommandSequence",
                lambda: second.LabwareTransferManipulatorController.GetLabware(
                    HandoverPosition=A1, IntermediateActions=[]
                ),
                "GetLabware refused: the robot is busy moving",
            ),
        ]
        assert not drive.done, "the refusals must have landed while the drive ran"
        finish(drive, timeout_s=60.0)
    finally:
        set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 0.0)
    assert len(messages) == 4
    assert first_motion.CurrentPointOfInterest.get() == "station_a_work"
    new_goals = robot_goals(cell)[goals_before:]
    assert [(name, outcome) for name, outcome, _, _ in new_goals] == [("/navigate_to_poi", "done")]
    assert_one_motion_at_a_time(robot_goals(cell))


def race(*starts: Callable[[], Any]) -> list[BaseException | None]:
    """Start commands from threads at the same instant; each one's error (None on success)."""
    barrier = threading.Barrier(len(starts))
    outcomes: list[BaseException | None] = [None] * len(starts)

    def run(index: int) -> None:
        barrier.wait()
        try:
            finish(starts[index](), timeout_s=120.0)
        except BaseException as error:  # noqa: BLE001 - collected for the assertions
            outcomes[index] = error

    threads = [threading.Thread(target=run, args=(index,)) for index in range(len(starts))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=150.0)
    return outcomes


def exactly_one_refused(outcomes: list[BaseException | None], match: str) -> str:
    errors = [error for error in outcomes if error is not None]
    assert len(errors) == 1, outcomes
    error = errors[0]
    assert isinstance(error, DefinedExecutionError) and error.identifier == "InvalidCommandSequence", error
    assert re.search(match, error.message), error.message
    return error.message


def test_two_clients_racing_through_a_transfer_get_one_run_and_one_clear_refusal(
    cell: Cell, second: SilaClient
) -> None:
    first_robot = cell.manipulator
    second_robot = second.LabwareTransferManipulatorController

    def prepare(robot: Any) -> Callable[[], Any]:
        return lambda: robot.PrepareForInput(
            HandoverPosition=A1, InternalPosition=1, LabwareType="", LabwareUniqueID=PLATE
        )

    def get(robot: Any) -> Callable[[], Any]:
        return lambda: robot.GetLabware(HandoverPosition=A1, IntermediateActions=[])

    exactly_one_refused(
        race(prepare(first_robot), prepare(second_robot)),
        r"PrepareForInput refused: the robot is (busy preparing for input|already prepared for input)",
    )
    finish(cell.site(A1[0]).PrepareForOutput(HandoverPosition=A1, InternalPosition=1))
    exactly_one_refused(
        race(get(first_robot), get(second_robot)),
        r"GetLabware (refused: the robot is busy getting labware|needs PrepareForInput first)",
    )
    # The one GetLabware that ran took the plate; both clients see the same robot.
    assert cell.location(PLATE) == (True, "", 1)
    assert [item.LabwareUniqueID for item in second.MobileRobotController.OnboardLabware.get()] == [PLATE]
    finish(cell.site(A1[0]).LabwareRemoved(HandoverPosition=A1))
    cell.place(B1, PLATE)
    assert cell.location(PLATE) == (False, *B1)
    occupied = cell.nest_occupied()
    assert occupied[B1] and not occupied[A1]
    assert_one_motion_at_a_time(robot_goals(cell))
