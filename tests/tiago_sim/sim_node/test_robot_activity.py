"""RobotActivity: every goal's state reaches /robot_state, however short the goal was.

Why: the publisher reads the activity 20 times a second; a 2 s drive at 50 times real time lasts
40 ms, and a SiLA client following RobotState saw Docked, Idle, Manipulating but never Navigating.
"""

from __future__ import annotations

from labware_interfaces.msg import RobotState

from tiago_skills.action_servers import RobotActivity

NAVIGATING, MANIPULATING = RobotState.STATE_NAVIGATING, RobotState.STATE_MANIPULATING


def test_a_goal_begun_and_ended_between_two_reads_is_reported_as_passed() -> None:
    activity = RobotActivity()
    activity.begin(NAVIGATING, "navigate_to_poi")
    activity.state = ""  # the goal ended before the publisher read
    report = activity.snapshot()
    assert (report.state, report.passed) == ("", ((NAVIGATING, "navigate_to_poi"),))
    assert activity.snapshot().passed == (), "each passed goal is reported once"


def test_the_running_goal_is_current_and_the_ones_before_it_passed() -> None:
    activity = RobotActivity()
    activity.begin(NAVIGATING, "undock")
    activity.state = ""
    activity.begin(MANIPULATING, "play_motion")
    report = activity.snapshot()
    assert (report.state, report.detail) == (MANIPULATING, "play_motion")
    assert report.passed == ((NAVIGATING, "undock"),)
    assert activity.snapshot().passed == ()


def test_a_fault_is_reported_after_the_goal_that_raised_it() -> None:
    activity = RobotActivity()
    activity.begin(MANIPULATING, "marker_motion")
    activity.state, activity.last_error = "", "marker_motion: MARKER_NOT_FOUND: marker not found: 3"
    report = activity.snapshot()
    assert report.state == RobotState.STATE_ERROR and "MARKER_NOT_FOUND" in report.detail
    assert report.passed == ((MANIPULATING, "marker_motion"),)
