"""Physical faults injected into the real simulation, seen through SiLA.

The faults come from tiago_sim.measuring.fault_injection.

- plate taken away while the robot reaches for it -> LabwareNotPicked; the inventory says "lost"
  (UnknownLabware), never "aboard";
- destination nest occupied -> PrepareForOutput refused before any motion (pose, joints and the sim
  node's goal log unchanged);
- plate slips out of the hotel mid-drive (physics drops it) -> PutLabware ends with LabwareNotPlaced,
  the inventory says "lost" (no sensor watches the floor; ground truth finds it there);
- plate knocked out of the destination nest the moment the gripper lets go -> PutLabware ends with
  LabwareNotPlaced (PLACE_FAILED: the nest's sensor sees no plate after the release), the
  inventory says "lost"; before, the robot reported a delivery nobody could see;
- marker occluded -> LabwareNotPicked: tests/sila_labware/servers/test_sila_servers.py
  (test_failed_get_is_labware_not_picked_and_inventory_stays_true).

The world is the default lab plus a second plate in station_b/2, the occupied destination.
Tests run in file order (occupied destination, drop, removal, knock) and hand the plate on.
A fault ends with someone putting the plate back (the fault parameter set to empty), as in a lab.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState
from sila2.framework import DefinedExecutionError

from labware_model.holders import FLOOR, Nest
from ros_bridge.topics import TopicMirror
from tests.helpers.sila_stack import start_stack
from tests.helpers.sim_parameters import set_node_parameter
from tests.helpers.transfer_steps import Cell, finish, together
from tests.helpers.world_variants import default_world_with

PLATE, BLOCKER = "plate_001", "plate_002"
A1, B1, B2 = ("station_a", 1), ("station_b", 1), ("station_b", 2)


def world_with_blocker(directory: Path) -> Path:
    """The default world with a second plate in station_b/2."""
    return default_world_with(directory / "two_plates.yaml", {BLOCKER: B2})


@pytest.fixture(scope="module")
def cell(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cell]:
    directory = tmp_path_factory.mktemp("physical")
    deployment = start_stack(directory, insecure=True, world=world_with_blocker(directory))
    yield Cell(deployment)
    deployment.stop()


def set_fault(cell: Cell, name: str, value: str) -> None:
    assert cell.deployment.runtime is not None
    set_node_parameter(cell.deployment.runtime, name, value)


def sim_log(cell: Cell) -> str:
    assert cell.deployment.options.log_dir is not None
    return (cell.deployment.options.log_dir / "sim_node.log").read_text(errors="replace")


def goal_lines(cell: Cell) -> list[str]:
    """The sim node's one log line per robot-level goal (name, outcome, simulated span)."""
    return [line for line in sim_log(cell).splitlines() if ": sim " in line and " .. " in line]


def expect_error(identifier: str, instance_or_call, match: str) -> DefinedExecutionError:
    with pytest.raises(DefinedExecutionError) as caught:
        instance_or_call() if callable(instance_or_call) else finish(instance_or_call, 120.0)
    assert caught.value.identifier == identifier, caught.value
    assert match in caught.value.message, caught.value.message
    return caught.value


def wait_nest(cell: Cell, nest: tuple[str, int], occupied: bool) -> None:
    assert cell.deployment.link is not None
    cell.deployment.link.wait_for_nest(Nest(*nest), occupied, timeout_s=5.0)


def assert_lost(cell: Cell, plate: str) -> None:
    """The inventory does not guess: the plate is reported lost, and not aboard."""
    expect_error("UnknownLabware", lambda: cell.location(plate), "is lost")
    assert cell.robot.MobileRobotController.OnboardLabware.get() == []


def test_occupied_destination_is_refused_before_any_motion(cell: Cell) -> None:
    cell.prepare_pick(A1, PLATE)
    cell.pick(A1)
    assert cell.location(PLATE)[0]
    runtime = cell.deployment.runtime
    assert runtime is not None
    joints = TopicMirror(runtime, JointState, "/joint_states", QoSProfile(depth=5))
    try:
        pose_before = cell.robot.MobileRobotController.RobotPose.get()
        joints_before = joints.wait_for_message(10.0)
        goals_before = goal_lines(cell)
        expect_error(
            "InvalidCommandSequence",
            lambda: finish(cell.manipulator.PrepareForOutput(HandoverPosition=B2, InternalPosition=1)),
            f"destination station_b/2 is occupied (holds {BLOCKER}); the robot did not move",
        )
        expect_error(
            "InvalidCommandSequence",
            lambda: finish(
                cell.site(B2[0]).PrepareForInput(
                    HandoverPosition=B2, InternalPosition=1, LabwareType="", LabwareUniqueID=PLATE
                )
            ),
            "nest station_b/2 is occupied",
        )
        time.sleep(0.5)  # a motion, had one started, would show by now
        pose_after = cell.robot.MobileRobotController.RobotPose.get()
        joints_after = joints.wait_for_message(10.0, lambda m: m.header.stamp != joints_before.header.stamp)
    finally:
        joints.destroy()
    assert goal_lines(cell) == goals_before, "a robot goal was sent"
    assert abs(pose_after.X - pose_before.X) < 1e-4 and abs(pose_after.Y - pose_before.Y) < 1e-4
    assert abs(pose_after.Theta - pose_before.Theta) < 1e-4
    before = dict(zip(joints_before.name, joints_before.position, strict=True))
    after = dict(zip(joints_after.name, joints_after.position, strict=True))
    assert max(abs(after[name] - before[name]) for name in before) < 2e-3
    assert cell.location(PLATE)[0], "the plate is still aboard"
    # State stays consistent: the plate goes back to the free nest it came from (no drive needed).
    cell.place(A1, PLATE)
    assert cell.location(PLATE) == (False, *A1)


def test_plate_dropped_mid_drive_is_labware_not_placed_and_reported_lost(cell: Cell) -> None:
    cell.prepare_pick(A1, PLATE)
    cell.pick(A1)
    set_fault(cell, "fault.drop_plate", PLATE)
    try:
        together(
            lambda: cell.site(B1[0]).PrepareForInput(
                HandoverPosition=B1, InternalPosition=1, LabwareType="", LabwareUniqueID=PLATE
            ),
            lambda: cell.manipulator.PrepareForOutput(HandoverPosition=B1, InternalPosition=1),
        )
        put = cell.manipulator.PutLabware(HandoverPosition=B1, IntermediateActions=[])
        expect_error("LabwareNotPlaced", put, "SLOT_EMPTY")
        assert f"plate {PLATE} slipped out of hotel slot 1 mid-drive" in sim_log(cell)
        assert_lost(cell, PLATE)
        assert cell.deployment.link is not None
        truth = cell.deployment.link.check_placement(PLATE)  # ground truth, for the check only
        assert truth.location == FLOOR, truth
        # The destination station does not claim a delivery its sensor does not see.
        expect_error(
            "InvalidCommandSequence",
            lambda: finish(cell.site(B1[0]).LabwareDelivered(HandoverPosition=B1)),
            "still sees no plate",
        )
    finally:
        set_fault(cell, "fault.drop_plate", "")  # someone picks the plate up and puts it in station_a/1
    wait_nest(cell, A1, occupied=True)
    # station_b/1 is still prepared for input: the scheduler redoes the robot's part and completes it.
    cell.prepare_pick(A1, PLATE)
    cell.pick(A1)
    finish(cell.manipulator.PrepareForOutput(HandoverPosition=B1, InternalPosition=1))
    finish(cell.manipulator.PutLabware(HandoverPosition=B1, IntermediateActions=[]))
    finish(cell.site(B1[0]).LabwareDelivered(HandoverPosition=B1))
    assert cell.location(PLATE) == (False, *B1)


def test_plate_taken_away_during_get_labware_is_labware_not_picked_and_the_next_pick_works(
    cell: Cell,
) -> None:
    """Runs last: the plate is in station_b/1 after the drop test's recovery."""
    cell.prepare_pick(B1, PLATE)
    get = cell.manipulator.GetLabware(HandoverPosition=B1, IntermediateActions=[])
    deadline = time.monotonic() + 30.0
    while not (get.progress or 0.0) > 0.0:  # the goal runs: the robot heads for the plate
        assert time.monotonic() < deadline and not get.done
        time.sleep(0.02)
    set_fault(cell, "fault.remove_plate", PLATE)
    try:
        # The robot runs ahead of this test's polling: taken away before the grasp, the fingers
        # close on nothing (GRASP_FAILED); taken out of the hand after it, the fingers say so at the
        # next check (PLATE_SLIPPED, seen in an idle CI run). Either is a pick the robot refuses.
        error = expect_error("LabwareNotPicked", get, "")
        assert "GRASP_FAILED" in error.message or "PLATE_SLIPPED" in error.message, error.message
        assert_lost(cell, PLATE)
        assert not cell.nest_occupied()[B1]
        assert cell.robot_state() != "Error"
        # The station's sensor agrees the nest is empty: the scheduler can close the hand-over.
        finish(cell.site(B1[0]).LabwareRemoved(HandoverPosition=B1))
    finally:
        set_fault(cell, "fault.remove_plate", "")  # someone puts the plate back (in station_a/1)
    wait_nest(cell, A1, occupied=True)
    # The robot is not left unable to work by the failed grasp: the next pick succeeds.
    cell.prepare_pick(A1, PLATE)
    cell.pick(A1)
    assert cell.location(PLATE) == (True, "", 1)


def test_plate_knocked_out_of_the_nest_after_the_release_is_labware_not_placed_and_reported_lost(
    cell: Cell,
) -> None:
    """Runs after the removal test: the plate is in hotel slot 1, the robot at station_a."""
    set_fault(cell, "fault.knock_plate", PLATE)
    try:
        together(
            lambda: cell.site(B1[0]).PrepareForInput(
                HandoverPosition=B1, InternalPosition=1, LabwareType="", LabwareUniqueID=PLATE
            ),
            lambda: cell.manipulator.PrepareForOutput(HandoverPosition=B1, InternalPosition=1),
        )
        put = cell.manipulator.PutLabware(HandoverPosition=B1, IntermediateActions=[])
        error = expect_error("LabwareNotPlaced", put, "PLACE_FAILED")
        assert "after release: the sensor of nest station_b/1 sees no plate" in error.message
        assert f"plate {PLATE} knocked out of its nest after the release" in sim_log(cell)
        assert_lost(cell, PLATE)
        expect_error(
            "InvalidCommandSequence",
            lambda: finish(cell.site(B1[0]).LabwareDelivered(HandoverPosition=B1)),
            "still sees no plate",
        )
    finally:
        set_fault(cell, "fault.knock_plate", "")  # someone puts the plate back in station_a/1
    wait_nest(cell, A1, occupied=True)
    # station_b/1 is still prepared for input: the scheduler redoes the robot's part and completes it.
    cell.prepare_pick(A1, PLATE)
    cell.pick(A1)
    finish(cell.manipulator.PrepareForOutput(HandoverPosition=B1, InternalPosition=1))
    finish(cell.manipulator.PutLabware(HandoverPosition=B1, IntermediateActions=[]))
    finish(cell.site(B1[0]).LabwareDelivered(HandoverPosition=B1))
    assert cell.location(PLATE) == (False, *B1)
