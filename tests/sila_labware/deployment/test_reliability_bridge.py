"""The bridge's own ROS thread dies in the middle of GetLabware (an rclpy callback raises, as an
InvalidStateError in a done-callback once did): the supervisor treats it like a dead child.

The SiLA command must end with its defined error within 10 s, every server must keep answering,
RobotState must say Error, a new ROS runtime must carry the same link (so the servers built on it
go on), the robot side is restarted and the inventory re-read from its fresh observations, and
the next transfer succeeds.
"""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest
from sila2.framework import DefinedExecutionError

from sila_labware.deployment.stack import Deployment
from sila_labware.deployment.supervisor import ROS_THREAD
from tests.helpers.ros_thread_faults import break_ros_thread
from tests.helpers.sila_stack import start_stack
from tests.helpers.transfer_steps import Cell, finish, wait_for_progress

PLATE = "plate_001"
A1, B1 = ("station_a", 1), ("station_b", 1)


@pytest.fixture(scope="module")
def cell(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cell]:
    deployment = start_stack(tmp_path_factory.mktemp("bridge_faults"), insecure=True)
    yield Cell(deployment)
    deployment.stop()


def wait_recovered(deployment: Deployment, timeout_s: float = 120.0) -> None:
    supervisor = deployment.supervisor
    assert supervisor is not None
    deadline = time.monotonic() + timeout_s
    while not supervisor.restarts or supervisor.recovering:
        assert not supervisor.failure, supervisor.failure
        assert time.monotonic() < deadline, "the bridge and the robot side are not back"
        time.sleep(0.2)


def test_the_ros_thread_dying_during_get_labware_is_recovered_and_the_next_transfer_succeeds(
    cell: Cell,
) -> None:
    deployment: Deployment = cell.deployment
    old_runtime, link = deployment.runtime, deployment.link
    assert old_runtime is not None and link is not None
    old_children = [child.pid for child in deployment.children.children]
    states: list[str] = []
    subscription = cell.robot.MobileRobotController.RobotState.subscribe()
    subscription.add_callback(states.append)

    cell.prepare_pick(A1, PLATE)
    get = cell.manipulator.GetLabware(HandoverPosition=A1, IntermediateActions=[])
    wait_for_progress(get, 0.35)
    break_ros_thread(old_runtime, "InvalidStateError: CANCELLED: <Future at 0x0 state=cancelled>")
    broken_at = time.monotonic()
    with pytest.raises(DefinedExecutionError, match="LabwareNotPicked") as raised:
        finish(get, timeout_s=10.0)
    assert time.monotonic() - broken_at < 10.0
    assert "no answer can come: the ROS thread ended (InjectedCallbackFailure: InvalidStateError" in str(
        raised.value
    )
    assert cell.robot.MobileRobotController.PointsOfInterest.get(), "the robot server answers"
    for station in cell.stations.values():
        assert station.LabwareTransferSiteController.AvailableHandoverPositions.get()

    wait_recovered(deployment)
    subscription.cancel()
    assert "Error" in states, states  # "robot side lost: the bridge's ROS thread ended (...); restarting"
    record = deployment.supervisor.restarts[-1]
    assert (record.child, record.exit_code) == (ROS_THREAD, None)
    assert record.ready_after_s is not None and record.ready_after_s < 60.0
    assert not old_runtime.thread_alive and old_runtime.failure.startswith("InjectedCallbackFailure")
    assert deployment.runtime is not old_runtime and deployment.runtime.running
    assert deployment.link is link and link.runtime is deployment.runtime, "the same link, a new runtime"
    new_children = [child.pid for child in deployment.children.children]
    assert len(new_children) == 2 and not set(new_children) & set(old_children), "a fresh robot side"

    # The fresh simulation put the plate back in station_a/1; the inventory says so from the new
    # observations, not the lost pick's guess. The source station is still prepared for output.
    assert cell.location(PLATE) == (False, "station_a", 1)
    assert cell.robot_state() != "Error"
    cell.prepare_pick(A1, PLATE, station_too=False)
    cell.pick(A1)
    cell.place(B1, PLATE)
    assert cell.location(PLATE) == (False, "station_b", 1)
    occupied = cell.nest_occupied()
    assert occupied[B1] and not occupied[A1]
