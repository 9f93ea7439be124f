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
