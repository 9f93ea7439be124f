"""The bridge when things go wrong on either side, against a real rclpy peer in another process:
a goal accepted after its caller gave up, a ROS thread ended by a raising callback, a ROS thread
that does not stop in time."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import pytest
from labware_interfaces.action import NavigateToPoi

from ros_bridge.actions import ActionCaller
from ros_bridge.errors import BridgeError, BridgeTimeout, GoalAbandoned
from ros_bridge.runtime import RosRuntime
from tests.helpers.echo_peer import goal_events, running_echo_peer
from tests.helpers.ros_thread_faults import break_ros_thread

GOAL_S = 1.0
ACCEPT_DELAY_S = 1.5
ACCEPT_TIMEOUT_S = 0.3


def until(condition: Callable[[], bool], timeout_s: float, what: str) -> None:
    deadline = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.05)


def test_a_goal_accepted_after_its_caller_gave_up_is_cancelled_and_never_runs(tmp_path: Path) -> None:
    """The peer answers goal requests after 1.5 s; the caller waits 0.3 s. The goal is reported
    failed (BridgeTimeout, withdrawn) and, when the late acceptance comes, cancelled at once: the
    peer logs it accepted then canceled, never succeeded, even well after its 1 s would be over."""
    goal_log = tmp_path / "goals.log"
    with (
        running_echo_peer(GOAL_S, accept_delay_s=ACCEPT_DELAY_S, goal_log=goal_log),
        RosRuntime("bridge_test_late_acceptance") as runtime,
    ):
        navigate = ActionCaller(runtime, NavigateToPoi, "/navigate_to_poi")
        navigate.wait_for_server(timeout_s=15.0)
        started = time.monotonic()
        with pytest.raises(BridgeTimeout, match="no answer to the goal request within 0.3 s.*withdrawn"):
            navigate.run(
                NavigateToPoi.Goal(poi="reader_poi"), timeout_s=10.0, accept_timeout_s=ACCEPT_TIMEOUT_S
            )
        assert time.monotonic() - started < 1.0, "the caller is answered when its wait ends"
        until(lambda: "canceled reader_poi" in goal_events(goal_log), 10.0, "the peer to cancel the goal")
        time.sleep(GOAL_S + 0.5)  # past the moment the goal would have succeeded
        assert goal_events(goal_log) == ["accepted reader_poi", "canceled reader_poi"]


def test_a_raising_callback_ends_the_ros_thread_and_the_runtime_says_why() -> None:
    runtime = RosRuntime("bridge_test_broken_thread").start()
    try:
        assert runtime.call(lambda: "alive") == "alive"
        break_ros_thread(runtime, "a done-callback raised InvalidStateError")
        until(lambda: not runtime.thread_alive, 5.0, "the ROS thread to end")
        assert runtime.failure == "InjectedCallbackFailure: a done-callback raised InvalidStateError"
        assert not runtime.running
        started = time.monotonic()
        with pytest.raises(BridgeError, match=r"not running: its ROS thread ended \(InjectedCallbackFailure"):
            runtime.call(lambda: None, timeout_s=5.0)
        assert time.monotonic() - started < 0.5, "refused at once, not after the call's timeout"
    finally:
        runtime.stop()
    assert runtime.failure, "stop() after a failure keeps the reason"


def test_stop_leaves_a_busy_ros_thread_its_objects_and_it_tears_them_down_itself() -> None:
    """stop() waits its timeout, then returns without touching rclpy: the ROS thread, still in a
    callback, destroys its node and context when the callback returns, and ends without a failure."""
    runtime = RosRuntime("bridge_test_busy_thread").start()
    busy = runtime.submit(lambda: time.sleep(1.0))
    time.sleep(0.1)  # the ROS thread is inside the callback now
    started = time.monotonic()
    runtime.stop(timeout_s=0.2)
    assert time.monotonic() - started < 0.6
    assert runtime.thread_alive, "the ROS thread is still in its callback"
    with pytest.raises(BridgeError, match="not running"):
        runtime.call(lambda: None)
    busy.result(timeout=5.0)
    until(lambda: not runtime.thread_alive, 5.0, "the ROS thread to end after its callback")
    assert runtime.failure == ""


def test_goals_still_open_when_the_runtime_ends_are_abandoned_at_once_naming_why(tmp_path: Path) -> None:
    """No answer can reach a goal once the ROS thread is gone: its waiter learns it at once, not
    after the step's timeout, whether the runtime was stopped or its thread died."""
    with running_echo_peer(30.0, goal_log=tmp_path / "goals.log"):
        for end, reason in (
            (lambda runtime: runtime.stop(), "the ROS runtime was stopped"),
            (
                lambda runtime: break_ros_thread(runtime, "boom"),
                r"the ROS thread ended \(InjectedCallbackFailure: boom\)",
            ),
        ):
            runtime = RosRuntime("bridge_test_open_goals").start()
            try:
                navigate = ActionCaller(runtime, NavigateToPoi, "/navigate_to_poi")
                navigate.wait_for_server(timeout_s=15.0)
                goal = navigate.send(NavigateToPoi.Goal(poi="rack_poi"))
                goal.wait_accepted(timeout_s=5.0)
                end(runtime)
                with pytest.raises(GoalAbandoned, match=f"/navigate_to_poi: no answer can come: {reason}"):
                    goal.wait(timeout_s=2.0)
            finally:
                runtime.stop()


def test_a_killed_action_server_does_not_count_as_ready() -> None:
    """After SIGKILL the peer's server may stay discovered until its DDS lease ends; only an
    answer counts. A goal sent on discovery alone reached the dead server and was never answered
    (a robot side restarted under load, in CI)."""
    with RosRuntime("bridge_test_killed_server") as runtime:
        navigate = ActionCaller(runtime, NavigateToPoi, "/navigate_to_poi")
        with running_echo_peer(GOAL_S) as peer:
            navigate.wait_for_server(timeout_s=15.0)
            assert navigate.answers(timeout_s=5.0), "a live server answers"
            peer.kill()
            peer.wait(timeout=10)
            assert navigate.is_ready(), "discovery forgot the killed server at once (here: after 20 s)"
            assert not navigate.answers(timeout_s=1.0), "a killed server answered"
            with pytest.raises(BridgeError, match="not available after 1.0 s"):
                navigate.wait_for_server(timeout_s=1.0)
