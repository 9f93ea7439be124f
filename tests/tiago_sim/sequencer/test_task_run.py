"""A task's remaining time: a step whose duration was measured counts down from that duration on the
robot's clock; any other step takes the sub-goal's own estimate. Plain values, no ROS."""

from __future__ import annotations

import pytest

from tiago_sim.sequencer.plans import Step
from tiago_sim.sequencer.step_durations import StepDurations, table_from_parameters
from tiago_sim.sequencer.task_run import TaskRun


class GetLabware:  # a task action as the sequencer sees it: its name and its feedback type
    Feedback = object


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


TO_HOTEL = Step("play_motion", {"motion_name": "NestApproach", "hotel_slot": 1}, "to hotel")
DRIVE = Step("navigate", {"poi": "somewhere_in_this_lab"}, "driving")
TUCK = Step("play_motion", {"motion_name": "Tuck"}, "arm tucked")
TABLE = table_from_parameters(
    {
        "navigate": 8.5,
        "GetLabware.play_motion.NestApproach.to_hotel": 3.3,
        "GetLabware.play_motion.Tuck.arm_tucked": 2.0,
    }
)


def test_a_measured_step_counts_down_on_the_robots_clock_whatever_the_sub_goal_says() -> None:
    clock = Clock()
    run = TaskRun.for_plan(None, GetLabware, [TO_HOTEL, TUCK], StepDurations(TABLE), clock)
    assert run.measured == [True, True] and run.durations == [3.3, 2.0]
    run.index = 0
    clock.now += 0.7
    run.step_remaining_s = 0.5  # the motion's own stage estimate, 2 s short (seen at pace 1)
    assert run.remaining_s() == pytest.approx(2.6 + 2.0)
    clock.now += 5.0  # overrun: nothing of this step is promised any more
    assert run.remaining_s() == pytest.approx(2.0)


def test_a_step_the_table_does_not_measure_takes_the_sub_goals_estimate() -> None:
    clock = Clock()
    run = TaskRun.for_plan(None, GetLabware, [DRIVE, TUCK], StepDurations(TABLE), clock)
    assert run.measured == [False, True]
    run.index = 0
    run.step_remaining_s = 6.0  # a drive's estimate from its planned path
    clock.now += 1.0
    assert run.remaining_s() == pytest.approx(6.0 + 2.0)


class Feedback:  # the fields a task's feedback message carries
    progress = 0.0
    phase = ""
    remaining_time_s = 0.0


class GoalHandle:
    def __init__(self) -> None:
        self.sent: list[Feedback] = []

    def publish_feedback(self, feedback: Feedback) -> None:
        self.sent.append(feedback)


class SubFeedback:  # a sub-goal's feedback message as rclpy hands it to the callback
    def __init__(self, progress: float) -> None:
        self.feedback = Feedback()
        self.feedback.progress, self.feedback.phase = progress, "moving"


def test_the_progress_sent_never_goes_back_when_a_step_estimates_itself_longer() -> None:
    handle = GoalHandle()
    run = TaskRun(handle, Feedback, [DRIVE, TUCK], [8.0, 2.0])
    run.index, run.step_progress = 0, 0.9
    run.publish()
    run.step_progress = 0.3  # the drive planned a longer way round
    run.publish()
    assert [f.progress for f in handle.sent] == pytest.approx([0.72, 0.72])
    run.index, run.step_progress = 1, 0.5
    run.publish()
    assert handle.sent[-1].progress == pytest.approx(0.9)


def test_feedback_of_a_sub_goal_whose_result_is_in_does_not_move_the_next_step() -> None:
    run = TaskRun(GoalHandle(), Feedback, [DRIVE, TUCK], [8.0, 2.0])
    on_feedback, silence = run.follow_sub_goal("driving")
    on_feedback(SubFeedback(0.4))
    assert run.step_progress == pytest.approx(0.4) and run.phase == "driving: moving"
    silence()
    run.index, run.step_progress, run.phase = 1, 0.0, "arm tucked"
    on_feedback(SubFeedback(0.95))  # travelled apart from the result, arrives late
    assert (run.step_progress, run.phase) == (0.0, "arm tucked")
