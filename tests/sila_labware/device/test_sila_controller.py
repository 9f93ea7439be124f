"""RobotController against a real rclpy peer in another process: step timeouts cancel the ROS goal,
refusals come before any goal is sent. The same paths, and more, run against the in-memory fake
in test_robot_controller_fast.py; these keep the real ROS back end honest."""

from __future__ import annotations

import time

import pytest

from labware_model.workcell import StationDescription, WorkcellDescription
from ros_bridge.robot_link import RobotLink
from sila_labware.device.errors import MotionFailed
from sila_labware.device.robot_backend import RobotBackend, StationBackend
from sila_labware.device.robot_controller import RobotController

WORKCELL = WorkcellDescription(
    stations=(StationDescription("reader", 1, "reader_poi"),),
    hotel_slots=2,
    pois=("reader_poi", "rack_poi"),
    dock_poi="dock_approach",
)


def test_a_step_past_its_timeout_is_cancelled_and_reported(link: RobotLink) -> None:
    controller = RobotController(link, WORKCELL, step_timeout_s=0.5)
    reports: list[float] = []
    started = time.monotonic()
    with pytest.raises(MotionFailed) as caught:
        controller.drive_to_poi("rack_poi", report=lambda progress, _remaining: reports.append(progress))
    assert caught.value.error_code == "CANCELED"
    assert "cancelled after" in caught.value.message
    assert time.monotonic() - started < 3.0, "the goal must be cancelled, not waited out"
    assert reports and all(0.0 <= value < 0.5 for value in reports)
    assert controller.sequence.phase.value == "idle"


def test_refusals_send_no_goal(link: RobotLink) -> None:
    controller = RobotController(link, WORKCELL)
    with pytest.raises(MotionFailed, match="no point of interest 'attic'") as caught:
        controller.drive_to_poi("attic")
    assert caught.value.error_code == "UNKNOWN_POI"
    before = link.robot_status(5.0).detail
    assert controller.stop_motion() is False  # nothing runs
    time.sleep(0.3)
    assert link.robot_status().detail == before  # the peer finished no goal meanwhile


def test_the_ros_link_is_the_controllers_back_end(link: RobotLink) -> None:
    assert isinstance(link, RobotBackend) and isinstance(link, StationBackend)
