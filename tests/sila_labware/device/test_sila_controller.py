"""RobotController against a real rclpy peer in another process: step timeouts cancel the ROS goal,
refusals come before any goal is sent, a cancel token stops its own command (before or during a
goal). The same paths, and more, run against the in-memory fake in test_robot_controller_fast.py;
these keep the real ROS back end honest."""

from __future__ import annotations

import concurrent.futures
import threading
import time

import pytest

from labware_model.workcell import StationDescription, WorkcellDescription
from ros_bridge.robot_link import RobotLink
from sila_labware.device.cancellation import CancelToken, cancellable, current_token
from sila_labware.device.errors import MotionFailed, ParameterError
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
    with pytest.raises(ParameterError, match="no point of interest 'attic'") as caught:
        controller.drive_to_poi("attic")
    assert caught.value.parameter == "PointOfInterest"
    before = link.robot_status(5.0).detail
    assert controller.stop_motion() is False  # nothing runs
    time.sleep(0.3)
    assert link.robot_status().detail == before  # the peer finished no goal meanwhile


def test_the_ros_link_is_the_controllers_back_end(link: RobotLink) -> None:
    assert isinstance(link, RobotBackend) and isinstance(link, StationBackend)


def test_a_command_cancelled_before_its_first_goal_sends_none(link: RobotLink) -> None:
    controller = RobotController(link, WORKCELL)
    token = CancelToken()
    assert controller.cancel_command(token, "cancelled by the test") is False  # it has no goal yet
    before = link.robot_status(5.0).detail
    with cancellable(token), pytest.raises(MotionFailed) as caught:
        controller.drive_to_poi("rack_poi")
    assert caught.value.error_code == "CANCELED"
    assert "cancelled by the test; DriveToPointOfInterest was not started" in caught.value.message
    assert controller.sequence.phase.value == "idle"
    time.sleep(0.3)
    assert link.robot_status().detail == before  # the peer finished no goal meanwhile


def test_cancel_command_stops_the_goal_of_its_own_command_only(link: RobotLink) -> None:
    controller = RobotController(link, WORKCELL)
    own, other = CancelToken(), CancelToken()
    outcome: concurrent.futures.Future[MotionFailed | None] = concurrent.futures.Future()

    def drive() -> None:
        with cancellable(own):
            try:
                controller.drive_to_poi("rack_poi")
                outcome.set_result(None)
            except MotionFailed as failure:
                outcome.set_result(failure)

    threading.Thread(target=drive, daemon=True).start()
    deadline = time.monotonic() + 2.0
    while controller.sequence.phase.value != "moving":  # the goal is about to be sent
        assert time.monotonic() < deadline
        time.sleep(0.01)
    time.sleep(0.3)  # and has been accepted (the peer's goals take 3 s)
    assert controller.cancel_command(other, "not this one") is False  # marks only that other command
    time.sleep(0.2)
    assert not outcome.done()
    started = time.monotonic()
    assert controller.cancel_command(own, "cancelled by the test") is True
    failure = outcome.result(timeout=3.0)
    assert time.monotonic() - started < 1.5, "the goal must be cancelled, not waited out"
    assert failure is not None and failure.error_code == "CANCELED"
    assert failure.message.startswith("DriveToPointOfInterest failed (CANCELED): cancelled by the test; ")


def test_a_cancel_token_keeps_its_first_reason_and_belongs_to_one_thread() -> None:
    token = CancelToken()
    assert (token.cancelled, token.reason) == (False, "")
    token.cancel("first")
    token.cancel("second")
    assert (token.cancelled, token.reason) == (True, "first")
    seen_elsewhere: list[CancelToken | None] = []
    with cancellable(token):
        assert current_token() is token
        worker = threading.Thread(target=lambda: seen_elsewhere.append(current_token()))
        worker.start()
        worker.join()
    assert seen_elsewhere == [None]
    assert current_token() is None
