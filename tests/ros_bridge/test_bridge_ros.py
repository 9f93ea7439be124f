"""The bridge against a real rclpy peer in another process, over DDS on this machine."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import pytest
from labware_interfaces.action import NavigateToPoi
from labware_interfaces.msg import RobotState
from labware_interfaces.srv import DescribeWorkcell

from ros_bridge.actions import ActionCaller, GoalProgress
from ros_bridge.errors import BridgeError, BridgeTimeout, ServerUnavailable
from ros_bridge.runtime import RosRuntime
from ros_bridge.services import ServiceCaller
from ros_bridge.topics import TopicMirror


@pytest.fixture(scope="module")
def runtime() -> Iterator[RosRuntime]:
    with RosRuntime("bridge_test_client") as started:
        yield started


def test_goal_crosses_processes_with_feedback_and_result(echo_server, runtime: RosRuntime) -> None:
    navigate = ActionCaller(runtime, NavigateToPoi, "/navigate_to_poi")
    navigate.wait_for_server(timeout_s=15.0)
    seen: list[GoalProgress] = []
    listener_threads: set[str] = set()

    def on_feedback(progress: GoalProgress) -> None:
        seen.append(progress)
        listener_threads.add(threading.current_thread().name)

    goal = navigate.send(NavigateToPoi.Goal(poi="reader_poi"), on_feedback=on_feedback)
    callback_threads: list[str] = []
    goal.add_callback(lambda _goal: callback_threads.append(threading.current_thread().name))
    goal.wait_accepted(timeout_s=5.0)
    assert goal.accepted is True
    outcome = goal.result(timeout_s=10.0)

    assert outcome.success and outcome.error_code == "" and outcome.status == "SUCCEEDED"
    assert outcome.message == "arrived at reader_poi"
    assert len(seen) >= 5, "expected feedback at 20 Hz for 1 s"
    progresses = [item.progress for item in seen]
    assert progresses == sorted(progresses) and 0.0 <= progresses[0] < 0.5
    assert all(item.phase == "driving" for item in seen[:-1]), "feedback, then the end"
    assert (seen[-1].progress, seen[-1].phase, seen[-1].remaining_time_s) == (1.0, "done", 0.0)
    assert seen[0].remaining_time_s > seen[-2].remaining_time_s
    assert goal.progress.progress == 1.0 and goal.progress.phase == "done"
    assert listener_threads == {"ros-bridge_test_client"}, "feedback must arrive on the ROS thread"
    assert goal.done and goal.success and goal.exception() is None
    assert callback_threads == ["ros-bridge_test_client"], "the ROS thread finishes the goal, once"


def test_abort_carries_error_code_and_message(echo_server, runtime: RosRuntime) -> None:
    navigate = ActionCaller(runtime, NavigateToPoi, "/navigate_to_poi")
    navigate.wait_for_server(timeout_s=15.0)
    outcome = navigate.run(NavigateToPoi.Goal(poi="nowhere"), timeout_s=10.0)
    assert not outcome.success
    assert outcome.status == "ABORTED"
    assert outcome.error_code == "UNKNOWN_POI"
    assert "nowhere" in outcome.message


def test_cancel_passes_through(echo_server, runtime: RosRuntime) -> None:
    navigate = ActionCaller(runtime, NavigateToPoi, "/navigate_to_poi")
    navigate.wait_for_server(timeout_s=15.0)
    goal = navigate.send(NavigateToPoi.Goal(poi="rack_poi"))
    goal.wait_accepted(timeout_s=5.0)
    time.sleep(0.3)
    assert goal.cancel(timeout_s=5.0)
    outcome = goal.result(timeout_s=5.0)
    assert outcome.status == "CANCELED" and outcome.error_code == "CANCELED"
    assert outcome.message.startswith("cancelled after")
    assert not goal.success and goal.cancel(timeout_s=5.0) is False, "an ended goal has nothing to cancel"


def test_topic_mirror_sees_publisher_in_other_process(echo_server, runtime: RosRuntime) -> None:
    changes: list[str] = []
    # the listener from the start: one added after the subscription may miss the first message
    mirror = TopicMirror(runtime, RobotState, "/robot_state", listeners=[lambda m: changes.append(m.detail)])
    first = mirror.wait_for_message(timeout_s=15.0)
    assert first.state == RobotState.STATE_IDLE and first.detail.startswith("finished ")
    time.sleep(0.5)
    assert mirror.received_count >= 3, "the peer publishes at 10 Hz"
    assert len(changes) == 1, "repeats of the same state are not changes"

    before = int(first.detail.split()[1])
    navigate = ActionCaller(runtime, NavigateToPoi, "/navigate_to_poi")
    navigate.wait_for_server(timeout_s=15.0)
    assert navigate.run(NavigateToPoi.Goal(poi="reader_poi"), timeout_s=10.0).success
    after = mirror.wait_for_message(
        timeout_s=5.0, predicate=lambda message: message.detail == f"finished {before + 1}"
    )
    assert after.current_poi == "reader_poi"
    assert changes[-1] == f"finished {before + 1}"
    mirror.destroy()


def test_service_call_and_missing_servers_are_named(echo_server, runtime: RosRuntime) -> None:
    describe = ServiceCaller(runtime, DescribeWorkcell, "/describe_workcell")
    describe.wait_for_service(timeout_s=15.0)
    response = describe.call(DescribeWorkcell.Request(), timeout_s=5.0)
    assert [(station.name, station.sub_positions) for station in response.stations] == [
        ("reader", 1),
        ("rack", 4),
    ]
    assert response.hotel_slots == 2

    missing_service = ServiceCaller(runtime, DescribeWorkcell, "/no_such_service")
    with pytest.raises(ServerUnavailable, match="/no_such_service"):
        missing_service.wait_for_service(timeout_s=0.5)
    missing_action = ActionCaller(runtime, NavigateToPoi, "/no_such_action")
    with pytest.raises(ServerUnavailable, match="/no_such_action"):
        missing_action.wait_for_server(timeout_s=0.5)


def test_stopped_runtime_refuses_work() -> None:
    runtime = RosRuntime("bridge_test_short_lived").start()
    assert runtime.call(lambda: runtime.node.get_name()) == "bridge_test_short_lived"
    started = time.monotonic()
    runtime.stop()
    assert time.monotonic() - started < 2.0
    with pytest.raises(BridgeError, match="not running"):
        runtime.call(lambda: None)


def test_call_the_ros_thread_never_started_is_withdrawn(runtime: RosRuntime) -> None:
    """A stalled ROS thread: the caller gets BridgeTimeout and the queued call never runs later
    (else a goal reported as not sent could still reach the robot)."""
    stall = runtime.submit(lambda: time.sleep(1.0))
    ran: list[bool] = []
    with pytest.raises(BridgeTimeout, match="withdrawn") as timeout:
        runtime.call(lambda: ran.append(True), timeout_s=0.2)
    assert "it was at: <lambda> (test_bridge_ros.py" in str(timeout.value), "names what the ROS thread ran"
    stall.result(timeout=5.0)
    assert runtime.call(lambda: "alive") == "alive"
    assert ran == [], "the withdrawn call ran after its caller gave up"
