"""Component faults: a robot-side node dies in the middle of GetLabware.

The SiLA command must end with a defined error within 10 s, every SiLA server must keep
answering, RobotState must say Error, the inventory must not keep a stale guess, and once the
supervisor has restarted the robot side the interrupted transfer completes (the source station is
still prepared for output, so the scheduler resumes with the robot's part). The scheduler names
the plate itself: the name survives the restart, where the fresh sensors confirm the plate (its
label, read again where the restarted simulation put it).
"""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Iterator

import pytest
from sila2.framework import DefinedExecutionError

from sila_labware.deployment.stack import Deployment
from tests.helpers.sila_stack import start_stack
from tests.helpers.transfer_steps import Cell, finish, wait_for_progress

PLATE = "scheduler-plate-7"
"""The scheduler's name for the plate whose label reads plate_001."""
KILL_AT_PROGRESS = 0.35
"""GetLabware past its final approach: the arm is on its way to the plate."""
A1, B1 = ("station_a", 1), ("station_b", 1)


@pytest.fixture(scope="module")
def cell(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cell]:
    deployment = start_stack(tmp_path_factory.mktemp("faults"), insecure=True)
    yield Cell(deployment)
    deployment.stop()


def kill_during_get_labware(cell: Cell, child_name: str, source: tuple[str, int]) -> list[str]:
    """Prepare a pick at `source`, start GetLabware, SIGKILL the child mid-way; return the RobotState
    values seen. Asserts the defined error arrives within 10 s of the kill."""
    states: list[str] = []
    subscription = cell.robot.MobileRobotController.RobotState.subscribe()
    subscription.add_callback(states.append)
    cell.prepare_pick(source, PLATE)
    get = cell.manipulator.GetLabware(HandoverPosition=source, IntermediateActions=[])
    wait_for_progress(get, KILL_AT_PROGRESS)
    deployment: Deployment = cell.deployment
    child = next(c for c in deployment.children.children if c.name == child_name)
    os.killpg(child.popen.pid, signal.SIGKILL)
    killed_at = time.monotonic()
    with pytest.raises(DefinedExecutionError, match="LabwareNotPicked.*robot side lost") as raised:
        finish(get, timeout_s=10.0)
    assert time.monotonic() - killed_at < 10.0
    assert child_name in str(raised.value)
    time.sleep(0.3)
    subscription.cancel()
    return states


def every_server_answers(cell: Cell) -> None:
    assert cell.robot.MobileRobotController.PointsOfInterest.get()
    for station in cell.stations.values():
        assert station.LabwareTransferSiteController.AvailableHandoverPositions.get()


def wait_recovered(deployment: Deployment, restarts: int, timeout_s: float = 120.0) -> float:
    supervisor = deployment.supervisor
    assert supervisor is not None
    deadline = time.monotonic() + timeout_s
    while len(supervisor.restarts) < restarts or supervisor.recovering:
        assert not supervisor.failure, supervisor.failure
        assert time.monotonic() < deadline, "robot side not back"
        time.sleep(0.2)
    ready_after_s = supervisor.restarts[-1].ready_after_s
    assert ready_after_s is not None
    return ready_after_s


def resume_transfer(cell: Cell, source: tuple[str, int], destination: tuple[str, int]) -> None:
    """The source station is still prepared for output: redo the robot's part, then the rest."""
    cell.prepare_pick(source, PLATE, station_too=False)
    cell.pick(source)
    cell.place(destination, PLATE)
    assert cell.location(PLATE) == (False, destination[0], destination[1])
    occupied = cell.nest_occupied()
    assert occupied[destination] and not occupied[source]


def test_sim_node_killed_during_get_labware_then_next_transfer_succeeds(cell: Cell) -> None:
    states = kill_during_get_labware(cell, "sim_node", A1)
    assert "Error" in states, states
    every_server_answers(cell)
    ready_after_s = wait_recovered(cell.deployment, restarts=1)
    assert ready_after_s < 60.0
    # the killed run's log is kept beside the new one's
    logs = cell.deployment.options.log_dir
    assert "sim node ready" in (logs / "sim_node.1.log").read_text()
    assert "sim node ready" in (logs / "sim_node.log").read_text()
    # A fresh simulation starts from the world file: the plate is back in station_a/1, and the
    # inventory says so from the new observations (not the lost pick's guess "aboard").
    assert cell.location(PLATE) == (False, "station_a", 1)
    assert cell.robot_state() != "Error"
    resume_transfer(cell, A1, B1)


def test_sequencer_killed_during_get_labware_then_next_transfer_succeeds(cell: Cell) -> None:
    # The plate is at station_b after the previous test (or back at station_a after a restart).
    source = B1 if cell.location(PLATE)[1] == "station_b" else A1
    destination = A1 if source == B1 else B1
    restarts_before = len(cell.deployment.supervisor.restarts)
    states = kill_during_get_labware(cell, "sequencer", source)
    assert "Error" in states, states
    every_server_answers(cell)
    wait_recovered(cell.deployment, restarts=restarts_before + 1)
    # The whole robot side restarted: the plate is where the world file puts it.
    aboard, station, index = cell.location(PLATE)
    assert not aboard and (station, index) == ("station_a", 1)
    if station != source[0]:
        # The source nest is empty now (the fresh simulation put the plate back at station_a):
        # the scheduler closes that station's handover, and the station checks its sensor.
        finish(cell.site(source[0]).LabwareRemoved(HandoverPosition=source))
        source, destination = A1, B1
        cell.prepare_pick(source, PLATE)
        cell.pick(source)
        cell.place(destination, PLATE)
    else:
        resume_transfer(cell, source, destination)
