"""When a command answers, the robot is in the state it reports, and every property says so.

Before: right after Undock finished, RobotState read Navigating; right after StopMotion answered
it read Navigating too, and a read a second later showed the heading 0.5 rad further on: the
commands answered on the action result, before the robot stood and before the state topic (and
the SiLA properties fed by it) showed it. Real servers, a real sila2 client, the real simulation.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from sila2.framework import DefinedExecutionError

from ros_bridge.robot_pace import WINDOW_S
from tests.helpers.sila_stack import start_stack
from tests.helpers.sim_parameters import set_node_parameter
from tests.helpers.transfer_steps import Cell, finish, wait_for_progress


@pytest.fixture(scope="module")
def cell(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cell]:
    deployment = start_stack(tmp_path_factory.mktemp("state_after"), insecure=True)
    yield Cell(deployment)
    deployment.stop()


def pose(cell: Cell) -> tuple[float, float, float]:
    reading = cell.robot.MobileRobotController.RobotPose.get()
    return reading.X, reading.Y, reading.Theta


def assert_stands_still(cell: Cell, wall_s: float = 1.0) -> None:
    """The pose read now is the pose a moment later (1 s of wall time is seconds of robot time).

    The pose is the localised one: the scans matched once the base stands (and the rest of a
    correction a drive was applying gently) may still move it by millimetres; a base still
    rolling or braking moves it by centimetres to decimetres."""
    before = pose(cell)
    time.sleep(wall_s)
    after = pose(cell)
    assert math.dist(before[:2], after[:2]) < 0.01, (before, after)
    assert abs(math.remainder(after[2] - before[2], math.tau)) < 0.01, (before, after)


def stop_mid_drive(cell: Cell, stop: Callable[[Any], None]) -> None:
    """Drive across the lab at real-time pace, stop half-way with `stop(drive)`, check the answer."""
    mobile = cell.robot.MobileRobotController
    set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 1.0)
    try:
        drive = mobile.DriveToPointOfInterest(PointOfInterest="station_b_work")
        wait_for_progress(drive, 0.3)
        stop(drive)
        assert mobile.RobotState.get() == "Idle"  # the moment the stop answered
        with pytest.raises(DefinedExecutionError):
            finish(drive)  # MotionStopped
    finally:
        set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 0.0)
    assert_stands_still(cell)


def test_undock_answers_with_the_robot_idle_off_the_dock(cell: Cell) -> None:
    mobile = cell.robot.MobileRobotController
    finish(mobile.Undock())
    assert mobile.RobotState.get() == "Idle"
    assert_stands_still(cell)


def test_a_drive_answers_with_the_robot_idle_at_its_point_of_interest(cell: Cell) -> None:
    mobile = cell.robot.MobileRobotController
    finish(mobile.DriveToPointOfInterest(PointOfInterest="station_a_work"))
    assert mobile.RobotState.get() == "Idle"
    assert mobile.CurrentPointOfInterest.get() == "station_a_work"
    assert_stands_still(cell)


def test_stop_motion_answers_once_the_robot_stands(cell: Cell) -> None:
    stop_mid_drive(cell, lambda _drive: cell.robot.MobileRobotController.StopMotion())


def test_a_cancel_answers_once_the_robot_stands(cell: Cell) -> None:
    stop_mid_drive(
        cell,
        lambda drive: cell.robot.CancelController.CancelCommand(
            CommandExecutionUUID=str(drive.execution_uuid)
        ),
    )


def test_dock_answers_with_the_robot_docked(cell: Cell) -> None:
    mobile = cell.robot.MobileRobotController
    finish(mobile.Dock())
    assert mobile.RobotState.get() == "Docked"


def remaining_while_running(instance: Any) -> list[tuple[float, float | None, float]]:
    """(progress, remaining wall seconds or None, when) as a client sees them until the command ends."""
    seen: list[tuple[float, float | None, float]] = []
    while not instance.done:
        # sila2's client writes the two fields of one update one after the other: keep a sample
        # only when the progress read before and after the remaining time agree
        before = instance.progress or 0.0
        remaining = instance.estimated_remaining_time
        if (instance.progress or 0.0) == before:
            seen.append((before, None if remaining is None else remaining.total_seconds(), time.monotonic()))
        time.sleep(0.01)
    return seen


def drive(cell: Cell) -> Any:
    return cell.robot.MobileRobotController.DriveToPointOfInterest(PointOfInterest="station_b_work")


def dock(cell: Cell) -> Any:
    return cell.robot.MobileRobotController.Dock()


def prepare_from_the_dock(cell: Cell) -> Any:
    """Undock (its remaining time counts the drive after it), then drive to station B."""
    return cell.manipulator.PrepareForInput(
        HandoverPosition={"Position": "station_b", "SubPosition": 2},
        InternalPosition=1,
        LabwareType="",
        LabwareUniqueID="",
    )


@pytest.mark.parametrize(
    ("start", "from_the_dock"),
    [(drive, False), (dock, False), (prepare_from_the_dock, True)],
    ids=["drive", "dock", "prepare"],
)
def test_remaining_time_is_never_zero_while_the_robot_still_moves(
    cell: Cell, start: Callable[[Cell], Any], from_the_dock: bool
) -> None:
    """Robot commands estimate the rest from the path and the robot's limits, in wall seconds at
    the current pace; where there is no estimate (between the undock and the drive of a Prepare)
    it is left unset: never 0 while work remains. The undock of a Prepare already counts the drive
    after it: its estimate holds at least half of what then remains (before, the drive's share was
    unknown until the drive began, and the Prepare from the dock was never within 10 % paced)."""
    mobile = cell.robot.MobileRobotController
    docked = mobile.RobotState.get() == "Docked"
    if docked != from_the_dock:
        finish(mobile.Dock() if from_the_dock else mobile.Undock())
    set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 4.0)  # slow enough to watch
    time.sleep(WINDOW_S + 0.5)  # the robot's pace is measured over a window: let the fast past leave it
    try:
        seen = remaining_while_running(start(cell))
    finally:
        set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 0.0)
    assert len(seen) > 20, "the command ended before a client could watch it"
    zero_while_moving = [(p, r) for p, r, _ in seen if p < 0.99 and r is not None and r <= 0.0]
    assert not zero_while_moving, zero_while_moving
    assert any(remaining is not None and remaining > 0.0 for _, remaining, _ in seen), seen
    if from_the_dock:
        ended = seen[-1][2]
        undocking = [(r, ended - at) for p, r, at in seen if p < 0.2 and r is not None]
        assert undocking, f"no remaining time while undocking: {seen[:20]}"
        assert all(r >= 0.5 * left for r, left in undocking), undocking
