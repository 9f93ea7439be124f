"""End to end: a plain SiLA client moves the plate from station_a to station_b in the standard's
order, through the robot and station servers, the ROS bridge and the real simulation. Success is
judged from physics ground truth, then checked against what the servers report."""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest

from labware_model.holders import Nest
from sila_labware.deployment.demo import run_demo
from sila_labware.deployment.stack import Deployment
from tests.helpers.sila_stack import client_for, start_stack


@pytest.fixture(scope="module")
def stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Deployment]:
    deployment = start_stack(tmp_path_factory.mktemp("sila_transfer"))
    yield deployment
    deployment.stop()


def test_plate_moves_from_station_a_to_station_b(stack: Deployment) -> None:
    robot = client_for(stack, stack.robot_server())
    subscription = robot.MobileRobotController.RobotState.subscribe()
    states: list[str] = []
    subscription.add_callback(states.append)

    started = time.monotonic()
    report = run_demo(stack, progress_stream=None)
    subscription.cancel()

    assert [step.name for step in report.steps] == [
        "A.PrepareForOutput + Robot.PrepareForInput",
        "Robot.GetLabware",
        "A.LabwareRemoved",
        "B.PrepareForInput + Robot.PrepareForOutput",
        "Robot.PutLabware",
        "B.LabwareDelivered",
    ]
    assert report.labware_id == "plate_001"
    assert (report.source, report.destination) == ("station_a/1", "station_b/1")
    assert report.plate_position_error_mm is not None and report.plate_position_error_mm < 5.0
    assert report.success, f"ground truth says the plate is not in its nest: {report}"
    assert report.sim_seconds > 0 and report.wall_seconds <= time.monotonic() - started + 1

    # The servers agree with the ground truth: the inventory, the robot, both stations' sensors.
    location = robot.LabwareInventory.LocateLabware(LabwareUniqueID="plate_001").Location
    assert (location.Aboard, location.Position, location.Index) == (False, "station_b", 1)
    assert robot.MobileRobotController.OnboardLabware.get() == []
    nests = {reading.nest: reading.occupied for reading in stack.link.nest_readings()}
    assert nests[Nest("station_a", 1)] is False and nests[Nest("station_b", 1)] is True
    assert "Navigating" in states and "Manipulating" in states, states

    # The protocol starts over: the robot is idle, and station_b now refuses input at the full nest.
    manipulator = robot.LabwareTransferManipulatorController
    instance = manipulator.GetLabware(HandoverPosition=("station_b", 1), IntermediateActions=[])
    while not instance.done:
        time.sleep(0.05)
    with pytest.raises(Exception, match="needs PrepareForInput first"):
        instance.get_responses()
