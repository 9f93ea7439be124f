"""The robot's pace (robot seconds per wall second) from its state stamps, and remaining times
reported in wall seconds, unset where there is no estimate. No ROS needed: plain values."""

from __future__ import annotations

import pytest

from ros_bridge.progress import CommandProgress, GoalProgress
from ros_bridge.robot_pace import RobotPace
from ros_bridge.workcell import RobotStatus


def status(stamp_s: float) -> RobotStatus:
    return RobotStatus("navigating", "", "", 0.0, 0.0, 0.0, (), "", stamp_s)


class WallClock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_the_pace_is_robot_time_over_wall_time_in_the_last_window() -> None:
    wall = WallClock()
    pace = RobotPace(window_s=2.0, wall_clock=wall)
    assert pace.factor == 1.0  # nothing measured yet
    for step in range(6):  # 0.5 s of wall time per report, 10 s of robot time: 20x
        wall.now = 100.0 + 0.5 * step
        pace.observe(status(10.0 * step))
    assert pace.factor == pytest.approx(20.0)
    assert pace.to_wall_s(30.0) == pytest.approx(1.5)
    for step in range(6, 12):  # the robot idles at 1x: the window forgets the fast part
        wall.now = 100.0 + 0.5 * step
        pace.observe(status(50.0 + 0.5 * (step - 5)))
    assert pace.factor == pytest.approx(1.0)


def test_a_set_pace_is_the_factor_while_the_measurement_agrees_and_not_when_it_does_not() -> None:
    wall = WallClock()
    pace = RobotPace(window_s=2.0, wall_clock=wall)
    pace.set_nominal(1.0)
    assert pace.factor == 1.0
    for step, arrival_jitter in enumerate(
        (0.0, 0.06, -0.05, 0.04, 0.0)
    ):  # state reports arrive late or early
        wall.now = 100.0 + 0.25 * step + arrival_jitter
        pace.observe(status(0.25 * step))
    assert pace.factor == 1.0, "jitter of a few reports does not move a remaining time off the set pace"
    for step in range(5, 10):  # a burst faster than the cap allows for long: still arrival jitter
        wall.now = 100.0 + 0.25 * step
        pace.observe(status(1.0 + 0.35 * (step - 4)))
    assert pace.factor == 1.0
    for step in range(10, 30):  # a machine too slow for the set pace: the robot's clock runs at 0.3
        wall.now = 100.0 + 0.25 * step
        pace.observe(status(2.75 + 0.075 * (step - 9)))
    assert pace.factor == pytest.approx(0.3)
    pace.set_nominal(None)  # as fast as the machine allows: the measurement only
    assert pace.factor == pytest.approx(0.3)


def test_a_restarted_robot_clock_starts_the_measurement_anew() -> None:
    wall = WallClock()
    pace = RobotPace(wall_clock=wall)
    for step, stamp in enumerate((100.0, 110.0, 1.0, 1.5)):
        wall.now = 100.0 + 0.5 * step
        pace.observe(status(stamp))
    assert pace.factor == pytest.approx(1.0)


def test_remaining_time_is_unset_where_there_is_no_estimate_and_never_zero_while_work_remains() -> None:
    reports: list[tuple[float, float | None]] = []
    progress = CommandProgress(
        lambda fraction, remaining: reports.append((round(fraction, 6), remaining)), lambda s: s / 10
    )
    undock = progress.step(0.0, 0.2, last=False)
    drive = progress.step(0.2, 1.0)
    undock(GoalProgress(0.5, "driving", 2.0))  # the drive after it has no estimate yet: unset
    drive(GoalProgress(0.0, "turning", 0.0))  # the robot side gave none yet: unset, not 0
    drive(GoalProgress(0.5, "driving", 30.0))  # 30 robot seconds at 10x: 3 wall seconds
    progress.finish()
    assert reports == [(0.1, None), (0.2, None), (0.6, pytest.approx(3.0)), (1.0, 0.0)]


def test_an_undock_that_counts_the_drive_after_it_reports_the_commands_remaining_time() -> None:
    """Undock told the POI it drives to next (then_poi): its remaining time holds that drive; at its
    end the command's is unset until the drive reports, never 0."""
    reports: list[tuple[float, float | None]] = []
    progress = CommandProgress(lambda fraction, remaining: reports.append((round(fraction, 6), remaining)))
    undock = progress.step(0.0, 0.2, last=False, counts_rest=True)
    drive = progress.step(0.2, 1.0)
    undock(GoalProgress(0.5, "undocking", 14.0))  # 2 s of undock and 12 s of the drive after it
    undock(GoalProgress(1.0, "done", 12.0))  # the undock's end: the next goal has not reported
    undock(GoalProgress(1.0, "done", 0.0))  # its result
    drive(GoalProgress(0.1, "driving", 11.0))
    assert reports == [(0.1, 14.0), (0.2, None), (0.2, None), (0.28, 11.0)]
