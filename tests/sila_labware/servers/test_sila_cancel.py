"""Cancelling a running GetLabware from a SiLA client with the robot's own StopMotion.

Two ways to cancel: a generic client uses the SiLA core feature CancelController (by execution
UUID; see test_sila_core_features.py); a client of our MobileRobotController can also call its
unobservable StopMotion, tested here: it cancels whatever ROS goal the robot runs, GetLabware's
included. The sequencer stops the running sub-action safely and reports CANCELED; GetLabware then
ends with its defined error LabwareNotPicked naming the cancel, after the inventory was settled
from the robot's observations.

Consistency is checked against physics ground truth (the simulation's CheckPlacement), and a
complete transfer must then succeed from wherever the plate is.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest
from sila2.framework import DefinedExecutionError

from labware_model.holders import GRIPPER, HotelSlot, Nest
from tests.helpers.sila_stack import start_stack
from tests.helpers.sim_parameters import set_node_parameter
from tests.helpers.transfer_steps import Cell, finish, wait_for_progress

PLATE = "plate_001"
A1, B1 = ("station_a", 1), ("station_b", 1)
CANCEL_AT_PROGRESS = 0.03
"""Early in the manipulation (the arm going to the bench), so the cancel lands mid-command."""


@pytest.fixture(scope="module")
def cell(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cell]:
    deployment = start_stack(tmp_path_factory.mktemp("cancel"), insecure=True)
    yield Cell(deployment)
    deployment.stop()


def cancel_mid_way(cell: Cell, get: Any) -> float:
    """Wait until GetLabware is under way, then StopMotion; returns when StopMotion was called."""
    wait_for_progress(get, CANCEL_AT_PROGRESS)
    cell.robot.MobileRobotController.StopMotion()
    return time.monotonic()


def test_stop_motion_cancels_get_labware_and_everything_stays_consistent(cell: Cell) -> None:
    cell.prepare_pick(A1, PLATE)
    # Paced at real time, the reach for the plate takes seconds of wall time, so the cancel lands
    # before the grasp however fast the machine or the motions are.
    set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 1.0)
    get = cell.manipulator.GetLabware(HandoverPosition=A1, IntermediateActions=[])
    try:
        stopped_at = cancel_mid_way(cell, get)
        with pytest.raises(DefinedExecutionError, match="CANCELED") as raised:
            finish(get, timeout_s=30.0)
    finally:
        set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 0.0)
        # Never leave the command running (its client stream would outlive the test).
        if not get.done:
            cell.robot.MobileRobotController.StopMotion()
            give_up_at = time.monotonic() + 30.0
            while not get.done and time.monotonic() < give_up_at:
                time.sleep(0.05)
    assert raised.value.identifier == "LabwareNotPicked", raised.value
    assert time.monotonic() - stopped_at < 10.0

    # The robot comes to rest, not in error (its state topic may lag the result by a few
    # messages); a second StopMotion then finds nothing to stop.
    at_rest_by = time.monotonic() + 3.0
    while cell.robot_state() != "Idle" and time.monotonic() < at_rest_by:
        time.sleep(0.05)
    assert cell.robot_state() == "Idle"
    cell.robot.MobileRobotController.StopMotion()

    # Inventory matches physics: the plate is in the source nest, in the hotel or held.
    where = cell.physical_location(PLATE)
    assert where in {Nest(*A1), HotelSlot(1), GRIPPER}, where
    assert cell.reported_location(PLATE) == where
    occupied = cell.nest_occupied()
    assert occupied[A1] == (where == Nest(*A1))
    assert not occupied[B1]

    # A complete transfer follows. Station A is still prepared for output (its handover is open),
    # so the scheduler redoes the robot's part, then closes A and places in B.
    assert where == Nest(*A1), f"cancel landed after the grasp: plate at {where}"
    cell.prepare_pick(A1, PLATE, station_too=False)
    cell.pick(A1)
    cell.place(B1, PLATE)
    assert cell.physical_location(PLATE) == Nest(*B1)
    assert cell.reported_location(PLATE) == Nest(*B1)
    assert cell.deployment.link is not None
    assert cell.deployment.link.check_placement(PLATE, Nest(*B1)).in_nest
