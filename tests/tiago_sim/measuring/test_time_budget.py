"""A transfer's time budget: the minima under TIAGo++'s limits, and reading a real run's logs.

Why: the budget says how much of a step's time some change could win back; a wrong minimum (a
joint's limit, the controller's ramp, a drive's profile) would point at the wrong step, and a log
line that drifts in format would leave steps without a minimum. The log excerpt below is copied
from a real run (`python -m tiago_sim.measuring.benchmark --seed 1 --budget`), trimmed to the
first seven goals.
"""

from __future__ import annotations

import math

import pytest

from robot_port.trajectory_timing import RAMP_S
from tiago_description import robot_model as rm
from tiago_description.joint_limits import velocity_limits
from tiago_sim.measuring import time_budget
from tiago_sim.measuring.budget_minima import drive_min_s, gripper_min_s, joint_move_min_s


def test_a_joint_move_is_timed_by_its_slowest_joint_under_the_ramp() -> None:
    limits = velocity_limits()
    assert limits["arm_right_1_joint"] == 1.95 and limits["torso_lift_joint"] == rm.TORSO_LIFT_SPEED
    start = {"arm_right_1_joint": 0.0, "arm_right_7_joint": 0.0, "torso_lift_joint": 0.1}
    end = {"arm_right_1_joint": 1.95, "arm_right_7_joint": -0.5, "torso_lift_joint": 0.1}
    # 1 s at 1.95 rad/s (joint 7 needs 0.28 s), plus the ramp up and down
    assert joint_move_min_s(start, end, limits) == pytest.approx((1.0 + RAMP_S, "arm_right_1_joint"))
    # a short move never reaches full speed: a triangle of 2 sqrt(t ramp)
    seconds, slowest = joint_move_min_s({"torso_lift_joint": 0.0}, {"torso_lift_joint": 0.0007}, limits)
    assert (seconds, slowest) == (pytest.approx(2 * math.sqrt(0.01 * RAMP_S)), "torso_lift_joint")
    assert joint_move_min_s(start, start, limits) == (0.0, "")


def test_a_straight_drive_forwards_and_backwards() -> None:
    # 3 m: 2 s to reach 1 m/s and 2 s to stop (1 m), 2 m at 1 m/s
    assert drive_min_s([(0.0, 0.0), (3.0, 0.0)], 0.0, 0.0) == pytest.approx((5.0, 3.0, 0.0))
    # undocking: 0.6 m straight back never reaches full speed, and turns nothing
    assert drive_min_s([(0.0, 0.0), (-0.6, 0.0)], 0.0, 0.0) == pytest.approx(
        (2 * math.sqrt(0.6 / rm.MAX_LINEAR_ACCEL), 0.6, 0.0)
    )


def test_a_turn_on_the_spot_and_a_turn_on_the_way() -> None:
    quarter = math.pi / 2  # 1 s to reach 1 rad/s, 1 s to stop, the rest at 1 rad/s
    assert drive_min_s([(1.0, 2.0)], 0.0, quarter) == pytest.approx((quarter + 1.0, 0.0, quarter))
    # half a turn onto a 0.5 m leg, then back: turning takes longer than driving
    seconds, length, turned = drive_min_s([(0.0, 0.0), (0.0, 0.5)], 0.0, 0.0)
    assert (length, turned) == pytest.approx((0.5, math.pi))
    assert seconds == pytest.approx(math.pi + 1.0)


def test_the_gripper_travels_at_its_speed_limit() -> None:
    assert gripper_min_s({"f": 0.045}, {"f": 0.038}) == pytest.approx(0.007 / rm.FINGER_SPEED)


_ROBOT_LOG = """\
pybullet build time: Jan 29 2025 23:17:20
2026-11-27 22:35:03,949 INFO tiago_skills.action_servers: /play_motion moved: odometry (-1.5000, \
-1.0000, 0.0000) -> (-1.5000, -1.0000, 0.0000); map (-1.4962, -1.0014, 0.0001) -> (-1.4962, -1.0014, \
0.0001); joints arm_right_2_joint -1.1000>-1.1507
2026-11-27 22:35:03,949 INFO tiago_skills.action_servers: /play_motion done: sim 4.467 .. 4.683 s, \
0.033 s of it with no motion running
2026-11-27 22:35:04,070 INFO tiago_skills.action_servers: /undock moved: odometry (-1.5000, -1.0000, \
0.0000) -> (-0.8985, -1.0000, -0.0000); map (-1.4962, -1.0014, 0.0001) -> (-0.8955, -1.0012, \
-0.0003); joints arm_left_1_joint 0.2000>0.1999, arm_left_4_joint 1.9400>2.3399, arm_left_6_joint \
1.3703>1.3698, arm_right_1_joint 0.1999>0.2000, arm_right_2_joint -1.1503>-1.1500, arm_right_6_joint \
1.3707>1.3718
2026-11-27 22:35:04,070 INFO tiago_skills.action_servers: /undock done: sim 4.700 .. 7.450 s, 0.050 \
s of it with no motion running
2026-11-27 22:35:04,116 INFO tiago_sim.sim_node.navigation: plan: 2 waypoints, 2.26 m, 0.4 ms: \
(-0.90, -1.00) -> (1.05, 0.14)
2026-11-27 22:35:04,425 INFO tiago_skills.action_servers: /navigate_to_poi moved: odometry (-0.8984, \
-1.0000, -0.0000) -> (1.0522, 0.1429, -0.0005); map (-0.8955, -1.0012, -0.0003) -> (1.0501, 0.1428, \
-0.0032); joints arm_left_4_joint 2.3043>2.3399, arm_right_1_joint 0.2000>0.1998, arm_right_3_joint \
-0.2000>-0.2001, arm_right_6_joint 1.3712>1.3716
2026-11-27 22:35:04,427 INFO tiago_skills.action_servers: /navigate_to_poi done: sim 7.483 .. 14.283 \
s, 0.033 s of it with no motion running
2026-11-27 22:35:04,999 INFO tiago_skills.marker_motion: marker 3 of station_a at [ 0.8465 -0.1378  \
0.84  ] in base, quaternion [ 0.50076 -0.49924 -0.49951  0.50049] (reprojection 0.09 px)
2026-11-27 22:35:05,443 INFO tiago_skills.action_servers: /marker_motion moved: odometry (1.0522, \
0.1429, -0.0005) -> (1.2700, 0.1438, 0.0058); map (1.0501, 0.1428, -0.0032) -> (1.2651, 0.1418, \
0.0040); joints arm_left_4_joint 2.3243>1.9403, arm_left_6_joint 1.3698>1.3703, arm_right_1_joint \
0.1998>0.1999, arm_right_6_joint 1.3713>1.3707, head_1_joint 0.0000>-0.3102, head_2_joint \
0.0001>-0.8432, torso_lift_joint 0.1500>0.3200
2026-11-27 22:35:05,443 INFO tiago_skills.action_servers: /marker_motion done: sim 14.283 .. 19.417 \
s, 0.350 s of it with no motion running
2026-11-27 22:35:05,769 INFO tiago_skills.action_servers: /play_motion moved: odometry (1.2700, \
0.1438, 0.0058) -> (1.2700, 0.1438, 0.0058); map (1.2650, 0.1420, 0.0038) -> (1.2650, 0.1420, \
0.0038); joints arm_left_1_joint 0.2000>0.2009, arm_right_1_joint 0.1999>0.3589, arm_right_2_joint \
-1.1500>-0.8793, arm_right_3_joint -0.2000>1.5802, arm_right_4_joint 1.9400>1.8404, \
arm_right_5_joint -1.5700>0.8586, arm_right_6_joint 1.3707>-1.3608, arm_right_7_joint 0.0000>2.0020, \
head_1_joint -0.3102>-0.3600, head_2_joint -0.8432>-0.9600
2026-11-27 22:35:05,769 INFO tiago_skills.action_servers: /play_motion done: sim 19.633 .. 21.783 s, \
0.067 s of it with no motion running
2026-11-27 22:35:05,796 INFO tiago_skills.action_servers: /gripper moved: odometry (1.2700, 0.1438, \
0.0058) -> (1.2700, 0.1438, 0.0058); map (1.2650, 0.1420, 0.0038) -> (1.2650, 0.1420, 0.0038); \
joints arm_left_1_joint 0.2009>0.2004, arm_right_1_joint 0.3589>0.3594, arm_right_7_joint \
2.0019>2.0011
2026-11-27 22:35:05,796 INFO tiago_skills.action_servers: /gripper done: sim 21.800 .. 21.837 s, \
0.033 s of it with no motion running
"""
_SEQUENCER_LOG = "\n".join(
    f"2026-11-27 22:35:03,952 INFO tiago_sim.sequencer.step_durations: {kind} took 0.50 s (estimated 4.56 s)"
    for kind in (
        "GetLabware:play_motion:Tuck:arm_tucked",
        "GetLabware:undock:undocking",
        "GetLabware:navigate:station_a_work:driving",
        "GetLabware:marker_motion:work_pose:final_approach",
        "GetLabware:play_motion:Benchtop:arm_to_bench",
        "GetLabware:gripper:open:opening",
    )
)


def test_a_real_runs_log_gives_a_row_per_goal_with_its_minimum() -> None:
    goals = time_budget.parse_goals(_ROBOT_LOG)
    rows = time_budget.budget(goals, time_budget.step_kinds(_SEQUENCER_LOG))
    assert [row.step.split(":")[1] for row in rows] == [
        "play_motion", "undock", "navigate", "marker_motion", "play_motion", "gripper",
    ]  # fmt: skip
    assert [row.took_s for row in rows] == pytest.approx([0.216, 2.75, 6.8, 5.134, 2.15, 0.037])
    assert rows[2].no_motion_s == pytest.approx(0.033)
    assert goals[2].plans == [[(-0.90, -1.00), (1.05, 0.14)]]
    tuck, undock, drive, approach, bench, gripper = (row.min_s for row in rows)
    assert tuck == pytest.approx(2 * math.sqrt(0.0507 / 1.95 * RAMP_S))
    # 0.6 m straight back; the left arm's 0.4 rad meanwhile is quicker
    assert undock == pytest.approx(2 * math.sqrt(0.6015 / rm.MAX_LINEAR_ACCEL), abs=0.01)
    # 2.25 m from the undocked pose to the POI, along the plan: 1 s up to speed, 1 s down
    assert drive == pytest.approx(math.hypot(1.0501 + 0.8955, 0.1428 + 1.0012) + 2.0, abs=0.01)
    assert "base 2.26 m" in rows[2].moved
    # the final approach: 0.22 m of base, but the torso's 0.17 m up at 0.07 m/s sets the minimum
    assert approach == pytest.approx(0.17 / rm.TORSO_LIFT_SPEED + RAMP_S)
    assert "torso_lift_joint 0.17 m" in rows[3].moved
    # to the bench: arm joint 6 turns 2.73 rad at 1.76 rad/s (the left arm settling by 1 mrad is no move)
    assert bench == pytest.approx(2.7315 / 1.76 + RAMP_S)
    assert "arm_right_6_joint 2.73 rad of 9 joints" in rows[4].moved
    assert (gripper, rows[5].moved) == (0.0, "nothing")  # already open; the arm settles within 1 mrad
    table = time_budget.format_table(rows, goals)
    assert "| between goals | 0.28 |" in table  # 0.017 + 0.033 + 0 + 0.216 + 0.017
    assert table.splitlines()[-1].startswith("| **all** | 17.37 | 11.21 | 6.16 | 0.85 |")


def test_the_skills_motion_line_reads_back() -> None:
    from tiago_skills.action_servers import describe_motion

    before = ((0.0, 0.0, 0.0), (1.0, 2.0, 0.1), {"torso_lift_joint": 0.15, "arm_right_1_joint": 0.2})
    after = ((-0.6, 0.0, 0.0), (0.4, 2.0, 0.1), {"torso_lift_joint": 0.32, "arm_right_1_joint": 0.2})
    log = (
        f"INFO tiago_skills.action_servers: /undock moved: {describe_motion(before, after)}\n"
        "INFO tiago_skills.action_servers: /undock done: sim 1.0 .. 3.5 s, 0.1 s of it with no motion running"
    )
    (goal,) = time_budget.parse_goals(log)
    assert goal.odometry == ((0.0, 0.0, 0.0), (-0.6, 0.0, 0.0))
    assert goal.believed == ((1.0, 2.0, 0.1), (0.4, 2.0, 0.1))
    assert goal.joints == {"torso_lift_joint": (0.15, 0.32)}  # a joint that held still is left out
    assert describe_motion(before, None) == "no readings"
