"""Which grasp twin an empty gripper takes: the one sooner at its target, and into a hotel pocket the
one whose straight line down the arm makes alone.

Why: the twin of the smallest largest joint change counted 0.2 m of torso (2.9 s at 0.07 m/s) as less
than 2.8 rad of an arm joint (about 1.5 s), so the fetch from the hotel lowered the torso; the twin
sooner above the left pocket then had no straight way down without the torso (IK_FAILED at waypoint
45 of 63 before the look ahead). The robot model's kinematics, as the skills run them.
"""

from __future__ import annotations

import numpy as np
import pytest

from tiago_description.motion_library import load_motions
from tiago_skills.arm_planning import ArmPlanning
from tiago_skills.grasp_twins import twin_pose, twin_with_a_way_down
from tiago_skills.joint_commands import move_s

ARM = "right"
BENCH_TORSO_M = 0.32


@pytest.fixture(scope="module")
def planning() -> ArmPlanning:
    return ArmPlanning(seed=1)


def tucked_at_the_bench() -> dict[str, float]:
    """Both arms tucked, the torso at the bench posture's height: where a put fetches its plate from."""
    motions = load_motions()
    joints: dict[str, float] = {"torso_lift_joint": BENCH_TORSO_M}
    for arm in ("left", "right"):
        for frame in motions.frames_for("Tuck", arm):
            joints.update(frame)
    return joints


def above_and_at_the_approach(planning: ArmPlanning, slot: int) -> tuple[np.ndarray, np.ndarray]:
    hotel = load_motions().hotel
    T_approach = planning.frame_pose({}, f"hotel_slot_{slot}") @ hotel.T_slot_grasp(True)
    T_carry = T_approach.copy()
    T_carry[2, 3] += hotel.carry_height_m
    return T_carry, T_approach


def test_a_joints_time_is_its_change_over_its_velocity_limit() -> None:
    torso = move_s({"torso_lift_joint": 0.32}, {"torso_lift_joint": 0.12})
    wrist = move_s({"arm_right_6_joint": 0.0}, {"arm_right_6_joint": 2.8})
    assert torso == pytest.approx(0.2 / 0.07) and wrist == pytest.approx(2.8 / 1.76)
    assert torso > wrist  # the order the largest change alone had the other way round


def test_slot_one_is_reached_from_the_bench_torso_and_the_way_down_needs_no_torso(
    planning: ArmPlanning,
) -> None:
    seed = tucked_at_the_bench()
    T_carry, T_approach = above_and_at_the_approach(planning, 1)
    twin = twin_with_a_way_down(planning, ARM, seed, (T_carry, T_approach), None)
    assert twin is not None
    above = {**seed, **planning.plan_joint_move(ARM, seed, twin_pose(T_carry, twin))}
    assert above["torso_lift_joint"] == pytest.approx(BENCH_TORSO_M), "the arm alone reaches above slot 1"
    line = planning.plan_line(ARM, above, twin_pose(T_approach, twin), use_torso=False)
    assert isinstance(line, list), line  # straight down by the arm alone
    other = {**seed, **planning.plan_joint_move(ARM, seed, twin_pose(T_carry, not twin))}
    assert move_s(seed, other) < move_s(seed, above), "the other twin is sooner above the pocket..."
    alone = planning.plan_line(ARM, other, twin_pose(T_approach, not twin), use_torso=False)
    assert isinstance(alone, str), "... and has no way down without the torso"


def test_a_twin_the_put_needs_wins_where_it_has_a_way_down(planning: ArmPlanning) -> None:
    seed = tucked_at_the_bench()
    above_below = above_and_at_the_approach(planning, 1)
    sooner = twin_with_a_way_down(planning, ARM, seed, above_below, None)
    assert twin_with_a_way_down(planning, ARM, seed, above_below, not sooner) == (not sooner)
