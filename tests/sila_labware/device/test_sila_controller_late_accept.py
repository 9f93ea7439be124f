"""RobotController against a robot side that accepts goals too late (a real rclpy peer in another
process, with its own module so that no other peer serves the same action meanwhile)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from labware_model.workcell import StationDescription, WorkcellDescription
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime
from sila_labware.device.errors import MotionFailed
from sila_labware.device.robot_controller import ControllerWaits, RobotController
from tests.helpers.echo_peer import goal_events, running_echo_peer

WORKCELL = WorkcellDescription(
    stations=(StationDescription("reader", 1, "reader_poi"),),
    hotel_slots=2,
    pois=("reader_poi", "rack_poi"),
    dock_poi="dock_approach",
)


def test_a_drive_the_robot_side_accepts_too_late_fails_and_never_runs(tmp_path: Path) -> None:
    """A robot side that answers goal requests after 2 s, a controller that waits 0.5 s: the command
    ends with MotionFailed naming the timeout, and the goal accepted later is cancelled at once
    instead of driving the robot while the scheduler believes it stands still."""
    goal_log = tmp_path / "goals.log"
    with (
        running_echo_peer(1.0, accept_delay_s=2.0, goal_log=goal_log),
        RosRuntime("late_accept_test") as runtime,
    ):
        link = RobotLink(runtime)
        link.robot_status(15.0)  # the peer is discovered
        controller = RobotController(link, WORKCELL, waits=ControllerWaits(accept_s=0.5))
        with pytest.raises(MotionFailed, match="withdrawn") as caught:
            controller.drive_to_poi("rack_poi")
        assert caught.value.error_code == "BridgeTimeout"
        assert controller.sequence.phase.value == "idle"
        deadline = time.monotonic() + 10.0
        while "canceled rack_poi" not in goal_events(goal_log):
            assert time.monotonic() < deadline, f"the late goal was not cancelled: {goal_events(goal_log)}"
            time.sleep(0.05)
        time.sleep(1.5)  # past the moment the drive would have ended
        assert goal_events(goal_log) == ["accepted rack_poi", "canceled rack_poi"]
        assert link.robot_status().current_poi != "rack_poi"
