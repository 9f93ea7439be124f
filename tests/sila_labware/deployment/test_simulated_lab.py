"""SimulatedLabController over SiLA: reset the lab, inject and clear faults, pace, simulated time.

Real parts: the whole stack (sim node with PyBullet, sequencer, bridge over DDS, SiLA servers over
gRPC). Ground truth (the sim node's /check_placement) only checks what the feature claims.
"""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest
from sila2.framework import DefinedExecutionError, ValidationError

from labware_model.holders import Nest
from tests.helpers.sila_stack import start_stack
from tests.helpers.transfer_steps import Cell, finish, wait_for_progress

PLATE = "plate_001"
A1, B1 = ("station_a", 1), ("station_b", 1)


@pytest.fixture(scope="module")
def cell(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cell]:
    deployment = start_stack(tmp_path_factory.mktemp("simulated_lab"), insecure=True)
    yield Cell(deployment)
    deployment.stop()


def lab_controls(cell: Cell):  # noqa: ANN201 - the sila2 dynamic client feature
    return cell.robot.SimulatedLabController


def reset(cell: Cell) -> float:
    started = time.monotonic()
    lab_controls(cell).ResetLab()
    return time.monotonic() - started


def test_the_feature_reports_simulated_time_pace_and_no_fault(cell: Cell) -> None:
    lab = lab_controls(cell)
    first = lab.SimulatedTime.get()
    assert first > 0.0
    # An idle robot reports its state (and with it the simulated time) every 0.5 s of wall time.
    deadline = time.monotonic() + 5.0
    while lab.SimulatedTime.get() <= first and time.monotonic() < deadline:
        time.sleep(0.1)
    assert lab.SimulatedTime.get() > first
    assert lab.RealTimeFactor.get() > 0.0
    assert lab.Pace.get() == 0.0
    assert lab.ActiveFaults.get() == []


def test_a_removed_plate_is_gone_until_the_reset_puts_it_back(cell: Cell) -> None:
    lab = lab_controls(cell)
    lab.InjectFault(Fault="RemovePlate", Target=PLATE)
    assert lab.ActiveFaults.get() == [f"RemovePlate {PLATE}"]
    assert not cell.deployment.link.check_placement(PLATE, Nest(*A1)).in_nest
    took_s = reset(cell)
    assert cell.deployment.link.check_placement(PLATE, Nest(*A1)).in_nest
    assert lab.ActiveFaults.get() == []
    assert took_s < 10.0


def test_a_reset_after_a_transfer_puts_plate_robot_and_inventory_back(cell: Cell) -> None:
    cell.transfer(A1, B1, PLATE)
    assert cell.location(PLATE) == (False, "station_b", 1)
    reset(cell)
    link = cell.deployment.link
    assert link.check_placement(PLATE, Nest(*A1)).in_nest
    assert cell.location(PLATE) == (False, "station_a", 1)
    assert link.wait_for_robot_status(lambda status: status.docked, 5.0).docked
    assert cell.nest_occupied()[A1] and not cell.nest_occupied()[B1]
    cell.transfer(A1, B1, PLATE)  # the protocol state is fresh: the same transfer runs again
    assert link.check_placement(PLATE, Nest(*B1)).in_nest
    reset(cell)


def test_reset_and_remove_are_refused_while_the_robot_drives(cell: Cell) -> None:
    lab = lab_controls(cell)
    motion = cell.robot.MobileRobotController
    finish(motion.Undock())
    lab.SetPace(Pace=1.0)  # a drive of seconds, not a tenth of one
    drive = motion.DriveToPointOfInterest(PointOfInterest="station_b_work")
    wait_for_progress(drive, 0.05)
    with pytest.raises(DefinedExecutionError, match="RobotBusy"):
        lab.ResetLab()
    with pytest.raises(DefinedExecutionError, match="RobotBusy"):
        lab.InjectFault(Fault="RemovePlate", Target=PLATE)
    lab.InjectFault(Fault="OccludeMarker", Target="station_b")  # meant to strike during a command
    lab.SetPace(Pace=0.0)
    finish(drive)
    lab.ClearFaults()
    assert lab.ActiveFaults.get() == []
    reset(cell)


def test_a_path_closed_mid_drive_fails_the_drive_with_navigation_failed(cell: Cell) -> None:
    lab = lab_controls(cell)
    motion = cell.robot.MobileRobotController
    finish(motion.Undock())
    lab.SetPace(Pace=10.0)  # the robot waits 20 s of simulated time for a way round
    lab.InjectFault(Fault="BlockPath", Target="closed")  # meant to strike during a command
    assert lab.ActiveFaults.get() == ["BlockPath closed"]
    drive = motion.DriveToPointOfInterest(PointOfInterest="station_b_work")
    with pytest.raises(DefinedExecutionError, match="NavigationFailed") as failure:
        finish(drive)
    assert "blocked by an obstacle not on the map" in str(failure.value)
    lab.ClearFaults()
    lab.SetPace(Pace=0.0)
    reset(cell)


def test_a_path_closed_during_prepare_is_the_standards_error_and_nothing_stays_prepared(cell: Cell) -> None:
    lab = lab_controls(cell)
    lab.SetPace(Pace=10.0)  # the robot waits 20 s of simulated time for a way round
    lab.InjectFault(Fault="BlockPath", Target="closed")
    with pytest.raises(DefinedExecutionError, match="InvalidCommandSequence") as failure:
        cell.prepare_pick(A1, PLATE, station_too=False)
    assert "nothing is prepared" in str(failure.value) and "NAVIGATION_FAILED" in str(failure.value)
    with pytest.raises(DefinedExecutionError, match="InvalidCommandSequence"):
        cell.pick(A1)  # not prepared: refused before anything moves
    assert cell.deployment.link.check_placement(PLATE, Nest(*A1)).in_nest
    lab.ClearFaults()
    lab.SetPace(Pace=0.0)
    reset(cell)


def test_an_occluded_marker_fails_the_pick_and_clearing_the_fault_lets_it_run(cell: Cell) -> None:
    lab = lab_controls(cell)
    lab.InjectFault(Fault="OccludeMarker", Target="station_a")
    assert lab.ActiveFaults.get() == ["OccludeMarker station_a"]
    cell.prepare_pick(A1, PLATE)
    with pytest.raises(DefinedExecutionError, match="MARKER_NOT_FOUND"):
        cell.pick(A1)
    assert cell.deployment.link.check_placement(PLATE, Nest(*A1)).in_nest, "the plate was not touched"
    lab.ClearFaults()
    assert lab.ActiveFaults.get() == []
    reset(cell)
    cell.transfer(A1, B1, PLATE)  # the marker is in view again
    assert cell.deployment.link.check_placement(PLATE, Nest(*B1)).in_nest
    reset(cell)


def test_a_plate_dropped_from_the_hotel_on_the_way_fails_the_put_and_is_not_claimed(cell: Cell) -> None:
    lab = lab_controls(cell)
    cell.prepare_pick(A1, PLATE)
    cell.pick(A1)
    lab.InjectFault(Fault="DropPlate", Target=PLATE)  # slips out of the hotel on the next drive
    with pytest.raises(DefinedExecutionError, match="PLATE_SLIPPED|SLOT_EMPTY"):
        cell.place(B1, PLATE)
    assert not cell.deployment.link.check_placement(PLATE, Nest(*B1)).in_nest
    with pytest.raises(DefinedExecutionError, match="UnknownLabware.*lost"):  # not claimed delivered
        cell.location(PLATE)
    reset(cell)
    assert cell.deployment.link.check_placement(PLATE, Nest(*A1)).in_nest


@pytest.mark.parametrize(
    ("fault", "target", "named"),
    [
        ("RemovePlate", "no_such_plate", "no_such_plate"),
        ("OccludeMarker", "station_z", "station_z"),
        ("BlockPath", "sideways", "sideways"),
        ("Explode", PLATE, "Explode"),
    ],
)
def test_bad_fault_input_is_a_validation_error_naming_it(
    cell: Cell, fault: str, target: str, named: str
) -> None:
    with pytest.raises(ValidationError, match=named):
        lab_controls(cell).InjectFault(Fault=fault, Target=target)
    assert lab_controls(cell).ActiveFaults.get() == []


def test_pace_is_set_at_run_time_and_refused_outside_its_range(cell: Cell) -> None:
    lab = lab_controls(cell)
    with pytest.raises(ValidationError):
        lab.SetPace(Pace=-1.0)
    lab.SetPace(Pace=2.0)
    assert lab.Pace.get() == 2.0
    started_wall, started_sim = time.monotonic(), lab.SimulatedTime.get()
    time.sleep(4.0)
    ratio = (lab.SimulatedTime.get() - started_sim) / (time.monotonic() - started_wall)
    lab.SetPace(Pace=0.0)
    # idle at the set pace, not the default idle's real time (1.0). SimulatedTime is the last
    # /robot_state's stamp, 0.5 s of wall time apart at most: each end may lag by one report, and a
    # loaded machine keeps the pace less well
    assert 1.3 < ratio < 2.7
