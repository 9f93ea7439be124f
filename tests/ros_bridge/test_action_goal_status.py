"""The status contract of a goal (ros_bridge.goal_status) and the progress rule, with no device.

Like ophyd's tests/test_status.py: every goal here is built standalone and finished by the test,
playing the creator's part (the ROS thread's, in a deployment). No DDS, no rclpy node.
"""

from __future__ import annotations

import logging
import math
import threading

import pytest

from ros_bridge.bluesky import ActionFailed, ActionStatus
from ros_bridge.errors import BridgeError, BridgeTimeout, GoalAbandoned, GoalRejected
from ros_bridge.goal_status import ActionGoal, ActionOutcome
from ros_bridge.progress import (
    RUNNING_GOAL_LEAST_REMAINING_S,
    CommandProgress,
    GoalProgress,
    MonotonicProgress,
)

ARRIVED = ActionOutcome(True, "", "arrived at reader_poi", "SUCCEEDED")
BLOCKED = ActionOutcome(False, "PATH_BLOCKED", "no path to reader_poi", "ABORTED")
SHORT_S = 0.01


def test_a_new_goal_is_pending_and_its_waits_time_out_with_the_bridge_error() -> None:
    goal = ActionGoal("/navigate_to_poi")
    assert not goal.done and not goal.success
    assert goal.accepted is None and goal.outcome is None
    assert goal.progress == GoalProgress()
    with pytest.raises(BridgeTimeout, match="/navigate_to_poi: no result within"):
        goal.wait(SHORT_S)
    with pytest.raises(BridgeTimeout, match="/navigate_to_poi: no result within"):
        goal.result(SHORT_S)
    with pytest.raises(BridgeTimeout, match="not finished within"):
        goal.exception(SHORT_S)
    with pytest.raises(BridgeTimeout, match="no answer to the goal request"):
        goal.wait_accepted(SHORT_S)


def test_a_successful_outcome_finishes_the_goal_at_full_progress() -> None:
    goal = ActionGoal("/navigate_to_poi")
    assert goal.set_accepted()
    goal.wait_accepted(SHORT_S)
    goal.update_progress(0.4, "driving", 3.0)
    assert goal.set_finished(ARRIVED)
    assert goal.done and goal.success and goal.accepted is True
    goal.wait(SHORT_S)
    assert goal.result(SHORT_S) is ARRIVED and goal.outcome is ARRIVED
    assert goal.exception(SHORT_S) is None
    assert goal.progress == GoalProgress(1.0, "done", 0.0, 1)


def test_an_unsuccessful_outcome_is_an_answer_not_an_exception() -> None:
    goal = ActionGoal("/navigate_to_poi")
    goal.set_accepted()
    goal.update_progress(0.4, "driving", 3.0)
    goal.set_finished(BLOCKED)
    assert goal.done and not goal.success
    goal.wait(SHORT_S)  # does not raise: the robot side answered
    assert goal.result(SHORT_S).error_code == "PATH_BLOCKED"
    assert goal.exception() is None
    assert goal.progress.progress == 0.4, "a failed goal keeps the progress it reached"


def test_a_rejected_goal_refuses_acceptance_and_answers_rejected() -> None:
    goal = ActionGoal("/dock")
    assert goal.set_rejected()
    assert goal.done and goal.accepted is False
    with pytest.raises(GoalRejected, match="/dock: the action server rejected the goal"):
        goal.wait_accepted(SHORT_S)
    outcome = goal.result(SHORT_S)
    assert (outcome.success, outcome.error_code, outcome.status) == (False, "REJECTED", "REJECTED")
    assert "rejected by the server" in outcome.message


def test_a_goal_finished_without_acceptance_counts_as_accepted() -> None:
    """A creator may answer at once (the fake robot does): acceptance follows from the answer."""
    goal = ActionGoal("/undock")
    goal.set_finished(ARRIVED)
    goal.wait_accepted(SHORT_S)
    assert goal.accepted is True and not goal.set_accepted()


def test_an_exception_before_acceptance_is_raised_by_every_wait() -> None:
    goal = ActionGoal("/get_labware")
    failure = BridgeError("/get_labware: goal request failed: context invalid")
    assert goal.set_exception(failure)
    assert goal.done and not goal.success and goal.outcome is None and goal.accepted is None
    assert goal.exception() is failure
    for wait in (goal.wait_accepted, goal.wait, goal.result):
        with pytest.raises(BridgeError) as raised:
            wait(SHORT_S)
        assert raised.value is failure


def test_an_exception_after_acceptance_leaves_acceptance_true() -> None:
    goal = ActionGoal("/get_labware")
    goal.set_accepted()
    goal.set_exception(BridgeError("result request failed"))
    goal.wait_accepted(SHORT_S)
    with pytest.raises(BridgeError, match="result request failed"):
        goal.wait(SHORT_S)


def test_a_callback_runs_once_on_the_thread_that_finishes_the_goal() -> None:
    goal = ActionGoal("/navigate_to_poi")
    calls: list[tuple[ActionGoal, str]] = []
    goal.add_callback(lambda finished: calls.append((finished, threading.current_thread().name)))
    finisher = threading.Thread(target=goal.set_finished, args=(ARRIVED,), name="fake-ros-thread")
    finisher.start()
    finisher.join()
    goal.set_finished(BLOCKED)
    goal.abort("too late")
    assert calls == [(goal, "fake-ros-thread")]


def test_a_callback_added_after_the_end_runs_at_once_on_the_callers_thread() -> None:
    goal = ActionGoal("/navigate_to_poi")
    goal.set_finished(ARRIVED)
    threads: list[str] = []
    goal.add_callback(lambda _goal: threads.append(threading.current_thread().name))
    assert threads == [threading.current_thread().name]


def test_a_broken_callback_is_logged_and_the_others_still_run(caplog: pytest.LogCaptureFixture) -> None:
    goal = ActionGoal("/dock")
    ran: list[str] = []

    def broken(_goal: ActionGoal) -> None:
        raise ValueError("bug in a callback")

    goal.add_callback(broken)
    goal.add_callback(lambda _goal: ran.append("second"))
    with caplog.at_level(logging.ERROR, logger="ros_bridge.goal_status"):
        assert goal.set_finished(ARRIVED), "a broken callback must not reach the finishing thread"
    assert ran == ["second"]
    assert "/dock: completion callback failed" in caplog.text


def test_the_first_end_wins_and_later_ones_return_false_at_debug_level(
    caplog: pytest.LogCaptureFixture,
) -> None:
    goal = ActionGoal("/put_labware")
    assert goal.set_finished(BLOCKED)
    with caplog.at_level(logging.DEBUG, logger="ros_bridge.goal_status"):
        assert not goal.set_finished(ARRIVED)
        assert not goal.set_exception(BridgeError("late"))
        assert not goal.set_rejected()
        assert not goal.abort("robot side lost")
    assert goal.outcome is BLOCKED and goal.exception() is None
    ignored = [record for record in caplog.records if "second end ignored" in record.getMessage()]
    assert len(ignored) == 4 and all(record.levelno == logging.DEBUG for record in ignored)


def test_racing_ends_from_many_threads_finish_the_goal_exactly_once() -> None:
    goal = ActionGoal("/navigate_to_poi")
    callbacks: list[ActionGoal] = []
    goal.add_callback(callbacks.append)
    start = threading.Barrier(8)
    wins: list[bool] = []

    def finish(index: int) -> None:
        start.wait()
        ended = goal.set_finished(ARRIVED) if index % 2 else goal.abort(f"abort {index}")
        wins.append(ended)

    threads = [threading.Thread(target=finish, args=(index,)) for index in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert sorted(wins) == [False] * 7 + [True]
    assert callbacks == [goal]


def test_abort_ends_a_waiting_goal_with_goal_abandoned_and_a_late_answer_is_ignored() -> None:
    goal = ActionGoal("/get_labware")
    goal.set_accepted()
    waiter_saw: list[BaseException] = []

    def wait_like_a_handler() -> None:
        try:
            goal.result(5.0)
        except BridgeError as error:
            waiter_saw.append(error)

    waiter = threading.Thread(target=wait_like_a_handler)
    waiter.start()
    assert goal.abort("robot side lost: sim ended (exit code -9)")
    waiter.join(1.0)
    assert not waiter.is_alive()
    assert len(waiter_saw) == 1 and isinstance(waiter_saw[0], GoalAbandoned)
    assert str(waiter_saw[0]) == "/get_labware: robot side lost: sim ended (exit code -9)"
    assert not goal.set_finished(ARRIVED), "the robot side's late answer changes nothing"
    assert isinstance(goal.exception(), GoalAbandoned) and not goal.success


def test_an_acceptance_that_does_not_come_in_time_withdraws_the_goal() -> None:
    """wait_accepted gives up: the creator is asked to cancel (it will, once accepted), the goal ends
    with BridgeTimeout, and the late acceptance, feedback and result change nothing."""
    cancel_requests: list[float] = []
    goal = ActionGoal(
        "/get_labware", cancel_request=lambda timeout_s: cancel_requests.append(timeout_s) or True
    )
    with pytest.raises(
        BridgeTimeout, match="/get_labware: no answer to the goal request within 0.0 s.*withdrawn"
    ):
        goal.wait_accepted(SHORT_S)
    assert cancel_requests == [5.0]
    assert goal.done and goal.accepted is None and isinstance(goal.exception(), BridgeTimeout)
    assert not goal.set_accepted() and not goal.update_progress(0.5, "grasping", 1.0)
    assert not goal.set_finished(ARRIVED) and not goal.success


def test_a_withdrawn_goal_that_ended_meanwhile_keeps_its_end() -> None:
    goal = ActionGoal("/dock")
    goal.set_rejected()
    assert not goal.withdraw("no answer in time")
    assert goal.outcome is not None and goal.outcome.status == "REJECTED"


def test_every_wait_on_a_goal_needs_a_bound() -> None:
    goal = ActionGoal("/undock")
    for wait in (goal.wait_accepted, goal.wait, goal.result, goal.exception):
        with pytest.raises(TypeError, match="needs a timeout"):
            wait(None)  # type: ignore[arg-type]


def test_progress_never_goes_down_and_listeners_see_what_is_shown() -> None:
    goal = ActionGoal("/navigate_to_poi")
    seen: list[GoalProgress] = []
    goal.add_progress_listener(seen.append)
    for estimate, remaining_s in [(0.2, 4.0), (0.5, 2.0), (0.3, 2.5), (math.nan, 2.0), (1.7, -1.0)]:
        assert goal.update_progress(estimate, "driving", remaining_s)
    assert [item.progress for item in seen] == [0.2, 0.5, 0.5, 0.5, 1.0]
    assert [item.remaining_time_s for item in seen] == [4.0, 2.0, 2.5, 2.0, 0.0]
    assert [item.feedback_count for item in seen] == [1, 2, 3, 4, 5]
    assert goal.progress == seen[-1]


def test_feedback_after_the_end_is_dropped() -> None:
    goal = ActionGoal("/navigate_to_poi")
    seen: list[GoalProgress] = []
    goal.add_progress_listener(seen.append)
    goal.update_progress(0.3, "driving", 2.0)
    goal.set_finished(BLOCKED)
    assert not goal.update_progress(0.9, "driving", 0.2)
    assert [item.progress for item in seen] == [0.3] and goal.progress.progress == 0.3


def test_a_broken_progress_listener_does_not_stop_the_others() -> None:
    goal = ActionGoal("/navigate_to_poi")
    seen: list[float] = []

    def broken(_progress: GoalProgress) -> None:
        raise RuntimeError("bug in a progress bar")

    goal.add_progress_listener(broken)
    goal.add_progress_listener(lambda progress: seen.append(progress.progress))
    assert goal.update_progress(0.5, "driving", 1.0)
    assert seen == [0.5]


def test_cancel_asks_the_creator_only_while_the_goal_runs() -> None:
    asked: list[float] = []

    def cancel_request(timeout_s: float) -> bool:
        asked.append(timeout_s)
        return True

    goal = ActionGoal("/navigate_to_poi", cancel_request=cancel_request)
    assert goal.cancel(2.5) is True and asked == [2.5]
    assert not goal.done, "cancelling asks; the creator finishes the goal when the robot answers"
    goal.set_finished(ActionOutcome(False, "CANCELED", "cancelled after 0.3 s", "CANCELED"))
    assert goal.cancel() is False and asked == [2.5]
    assert ActionGoal("/dock").cancel() is False, "a goal nobody can cancel says so"


# --- the progress rule ---


def test_monotonic_progress_clamps_and_keeps_the_highest() -> None:
    fraction = MonotonicProgress()
    shown = [fraction.advance(estimate) for estimate in (-0.5, 0.25, 0.1, math.inf, 2.0, 0.9)]
    assert shown == [0.0, 0.25, 0.25, 0.25, 1.0, 1.0]
    assert MonotonicProgress(0.6).fraction == 0.6


def test_command_progress_maps_each_goal_into_its_share_and_never_goes_down() -> None:
    reports: list[tuple[float, float]] = []
    command = CommandProgress(lambda fraction, remaining_s: reports.append((fraction, remaining_s)))
    undock, drive = command.step(0.0, 0.2), command.step(0.2, 1.0)
    undock(GoalProgress(0.5, "undocking", 1.0))  # 0 + 0.2 * 0.5 = 0.1
    undock(GoalProgress(1.0, "undocking", 0.0))  # 0.2
    drive(GoalProgress(0.0, "driving", 8.0))  # 0.2 + 0.8 * 0 = 0.2
    drive(GoalProgress(0.5, "driving", 4.0))  # 0.2 + 0.8 * 0.5 = 0.6
    command.step(0.0, 0.5)(GoalProgress(0.8, "retry", 3.0))  # 0.4 would go down: 0.6 stays
    command.report(0.55, -1.0)  # below again; remaining time is never negative
    command.finish()
    assert [round(fraction, 9) for fraction, _ in reports] == [0.1, 0.2, 0.2, 0.6, 0.6, 0.6, 1.0]
    assert [remaining_s for _, remaining_s in reports] == [1.0, 0.0, 8.0, 4.0, 3.0, 0.0, 0.0]
    assert command.fraction == 1.0


def test_command_progress_without_a_watcher_still_keeps_its_fraction() -> None:
    command = CommandProgress(None)
    command.step(0.5, 1.0)(GoalProgress(0.5))
    assert command.fraction == 0.75


# --- a consumer of the contract: the Bluesky status, with no device ---


def test_the_bluesky_status_follows_the_goal_through_its_callback() -> None:
    goal = ActionGoal("/navigate_to_poi")
    status = ActionStatus(None, goal, label="to reader")
    percents: list[float] = []
    status.watch(lambda **kwargs: percents.append(kwargs["current"]) if "current" in kwargs else None)
    goal.update_progress(0.25, "driving", 3.0)
    goal.set_finished(ARRIVED)
    status.wait(timeout=1.0)
    assert status.success and status.outcome is ARRIVED
    assert percents == [0.0, 25.0, 100.0]


def test_the_bluesky_status_fails_with_the_goals_error_code_or_exception() -> None:
    failed_goal = ActionGoal("/navigate_to_poi")
    failed = ActionStatus(None, failed_goal)
    failed_goal.set_finished(BLOCKED)
    with pytest.raises(ActionFailed) as failure:
        failed.wait(timeout=1.0)
    assert failure.value.error_code == "PATH_BLOCKED" and failure.value.status == "ABORTED"

    lost_goal = ActionGoal("/get_labware")
    lost = ActionStatus(None, lost_goal)
    lost_goal.abort("robot side lost")
    with pytest.raises(GoalAbandoned, match="robot side lost"):
        lost.wait(timeout=1.0)


def test_a_running_goal_never_reports_less_remaining_time_than_a_feedback_period() -> None:
    """A SiLA client counts the last estimate down to 0 by itself: while the goal still runs, the
    command says at least RUNNING_GOAL_LEAST_REMAINING_S, so the count never reaches 0 before the
    robot's next report. The goal's end still says 0."""
    reports: list[tuple[float, float | None]] = []
    drive = CommandProgress(lambda fraction, remaining_s: reports.append((fraction, remaining_s))).step(
        0.0, 1.0
    )
    drive(GoalProgress(0.97, "aligning", 0.1))
    drive(GoalProgress(1.0, "done", 0.0))
    assert reports == [(0.97, RUNNING_GOAL_LEAST_REMAINING_S), (1.0, 0.0)]
