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
    """The pose read now is the pose a moment later (1 s of wall time is seconds of robot time)."""
    before = pose(cell)
    time.sleep(wall_s)
    after = pose(cell)
    assert math.dist(before[:2], after[:2]) < 0.002, (before, after)
    assert abs(math.remainder(after[2] - before[2], math.tau)) < 0.005, (before, after)


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
