"""ActionStatus and the robot device's readings against a real rclpy peer in another process.

The peer (tests/helpers/ros_echo_server.py, started by conftest.py) serves /navigate_to_poi with
feedback at 20 Hz for 2 s per goal and publishes /robot_state at 10 Hz (and serves no task-level
actions): quick, real DDS, no simulation needed.
"""

from __future__ import annotations

import io
import logging
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from bluesky import RunEngine
from bluesky import plan_stubs as bps
from bluesky.utils import FailedStatus, TerminalProgressBar
from labware_interfaces.action import NavigateToPoi
from ophyd import Device
from ophyd.utils import StatusTimeoutError

from labware_model.holders import Nest
from ros_bridge.actions import ActionCaller
from ros_bridge.bluesky import ActionFailed, ActionStatus, LabwareTransferRobot
from ros_bridge.bluesky.demo import run_bluesky_demo
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime

GOAL_SECONDS = 2.0
ECHO_GOAL_SECONDS = GOAL_SECONDS  # read by the echo_server fixture (conftest.py)


@pytest.fixture(scope="module")
def runtime(echo_server: subprocess.Popen) -> Iterator[RosRuntime]:
    with RosRuntime("bluesky_status_test") as started:
        yield started


@pytest.fixture(scope="module")
def navigate(runtime: RosRuntime) -> ActionCaller:
    caller = ActionCaller(runtime, NavigateToPoi, "/navigate_to_poi")
    caller.wait_for_server(timeout_s=15.0)
    return caller


class NavigatingBase(Device):
    """The smallest movable over an action: set(poi) drives there (for RunEngine tests)."""

    def __init__(self, navigate: ActionCaller, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self._navigate = navigate
        self.statuses: list[ActionStatus] = []

    def set(self, poi: str) -> ActionStatus:
        status = ActionStatus(self, self._navigate.send(NavigateToPoi.Goal(poi=poi)), label=f"to {poi}")
        self.statuses.append(status)
        return status

    def stop(self, *, success: bool = False) -> None:
        for status in self.statuses:
            status.cancel_goal()


def test_watchers_get_percent_progress_and_the_status_finishes(navigate: ActionCaller) -> None:
    calls: list[dict[str, Any]] = []
    status = ActionStatus(None, navigate.send(NavigateToPoi.Goal(poi="reader_poi")), label="to reader")
    status.watch(lambda **kwargs: calls.append(kwargs))
    bar = TerminalProgressBar([status], delay_draw=0.2)
    bar.fp = io.StringIO()  # draw into a buffer instead of the terminal
    time.sleep(GOAL_SECONDS / 2)
    bar_mid_goal = list(bar.meters)
    status.wait(timeout=GOAL_SECONDS + 5.0)
    bar.clear()

    assert status.success and status.outcome is not None and status.outcome.message == "arrived at reader_poi"
    progress_calls = [call for call in calls if "current" in call]
    assert len(progress_calls) >= 10, "expected a watcher call per feedback (20 Hz)"
    assert all(call["name"] == "to reader" and call["unit"] == "%" for call in progress_calls)
    assert all(call["initial"] == 0.0 and call["target"] == 100.0 for call in progress_calls)
    currents = [call["current"] for call in progress_calls]
    assert currents == sorted(currents) and currents[-1] == 100.0
    fractions = [call["fraction"] for call in progress_calls]
    assert fractions[-1] == 0.0 and max(fractions) > 0.5, "fraction is what remains"
    assert progress_calls[1]["time_remaining"] > progress_calls[-2]["time_remaining"]
    assert progress_calls[-1]["time_elapsed"] >= GOAL_SECONDS * 0.9
    assert "%" in bar_mid_goal[0] and "to reader" in bar_mid_goal[0], bar_mid_goal
    assert "to reader" in bar.fp.getvalue()


def test_an_aborted_action_fails_the_status_with_code_and_message(navigate: ActionCaller) -> None:
    status = ActionStatus(None, navigate.send(NavigateToPoi.Goal(poi="nowhere")))
    with pytest.raises(ActionFailed) as failure:
        status.wait(timeout=10.0)
    assert failure.value.error_code == "UNKNOWN_POI"
    assert failure.value.message == "no point of interest named 'nowhere'"
    assert failure.value.status == "ABORTED"
    assert not status.success


def test_a_timed_out_status_cancels_its_goal(navigate: ActionCaller) -> None:
    goal = navigate.send(NavigateToPoi.Goal(poi="rack_poi"))
    status = ActionStatus(None, goal, timeout=0.5)
    with pytest.raises(StatusTimeoutError):
        status.wait(timeout=5.0)
    outcome = goal.result(timeout_s=5.0)
    assert outcome.status == "CANCELED", outcome
    assert outcome.message.startswith("cancelled after")


def test_runengine_reports_the_action_message_and_stop_cancels(navigate: ActionCaller) -> None:
    base = NavigatingBase(navigate, name="base")
    engine = RunEngine({}, context_managers=[])
    engine(bps.mv(base, "reader_poi"))
    assert base.statuses[-1].success

    with pytest.raises(FailedStatus) as failure:
        engine(bps.mv(base, "nowhere"))
    assert isinstance(failure.value.__cause__, ActionFailed)
    assert "UNKNOWN_POI" in str(failure.value.__cause__) and "'nowhere'" in str(failure.value.__cause__)

    status = base.set("rack_poi")
    time.sleep(0.3)
    base.stop()
    with pytest.raises(ActionFailed) as cancelled:
        status.wait(timeout=5.0)
    assert cancelled.value.error_code == "CANCELED"


def test_robot_device_reads_robot_state_and_refuses_unknown_tasks(runtime: RosRuntime) -> None:
    link = RobotLink(runtime)
    robot = LabwareTransferRobot(
        link,
        storage=Nest("rack", 2),
        beam=Nest("reader", 1),
        labware_id="plate_7",
        name="robot",
    )
    status = robot.trigger()
    status.wait(timeout=10.0)
    reading = robot.read()
    assert reading["robot_state"]["value"] == "idle"
    assert reading["robot_detail"]["value"].startswith("finished ")
    assert reading["robot_carried_labware"]["value"] == ""
    description = robot.describe()
    assert description["robot_state"]["dtype"] == "string"
    assert description["robot_base_x"]["dtype"] == "number"
    configuration = robot.read_configuration()
    assert configuration["robot_storage_site"]["value"] == "rack/2"
    assert configuration["robot_beam_site"]["value"] == "reader/1"
    assert configuration["robot_labware_id"]["value"] == "plate_7"
    assert set(robot.hints["fields"]) == {"robot_state", "robot_carried_labware"}
    with pytest.raises(ValueError, match="unknown task 'dance'"):
        robot.set("dance")


def test_demo_without_the_task_servers_exits_1_naming_what_is_missing(
    runtime: RosRuntime, caplog: pytest.LogCaptureFixture
) -> None:
    world = Path(__file__).resolve().parents[2] / "lab_description" / "worlds" / "default.yaml"
    with caplog.at_level(logging.ERROR, logger="ros_bridge.bluesky.demo"):
        # per server: time for a fresh participant to discover the echo server's navigate action
        # on a busy machine
        assert run_bluesky_demo(world, ready_timeout_s=8.0) == 1
    assert "action server /dock (Dock) not available" in caplog.text
