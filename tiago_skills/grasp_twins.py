"""A top-down grasp's two twins (the fingers swapped by a half turn about the approach) and which one
an empty gripper takes: the one sooner at its target under the joints' velocity limits.

Why apart from the behaviours: the hotel's way down and a single move choose by the same timing, and
the put's reach check and the bench route need the flip too. Pure computation on the robot model.
"""

from __future__ import annotations

import numpy as np

from tiago_description.transforms import make_transform
from tiago_skills.arm_planning import ArmPlanning
from tiago_skills.joint_commands import move_s

# Half-turn about the grasp x axis: the same top-down grasp with the fingers swapped.
FLIP_ABOUT_APPROACH = make_transform(rotation=np.diag([1.0, -1.0, -1.0]))


def twin_pose(T_base_grasp: np.ndarray, flip: bool) -> np.ndarray:
    return T_base_grasp @ FLIP_ABOUT_APPROACH if flip else T_base_grasp


def twin_times(
    planning: ArmPlanning, arm: str, T_base_grasp: np.ndarray, seed: dict[str, float], twins: list[bool]
) -> dict[bool, float]:
    """Each of `twins` the arm reaches in one joint move (the arm alone if it can, as the move goes),
    with the slowest joint's time to it: 0.2 m of torso takes 2.9 s, 2.8 rad of an arm joint 1.5 s."""
    duration = {}
    for flip in twins:
        joints = planning.plan_joint_move(arm, seed, twin_pose(T_base_grasp, flip))
        if joints is not None:
            duration[flip] = move_s(seed, joints)
    return duration


def twin_with_a_way_down(
    planning: ArmPlanning,
    arm: str,
    seed: dict[str, float],
    above_below: tuple[np.ndarray, np.ndarray],
    wanted: bool | None,
) -> bool | None:
    """For an empty gripper: the twin to move above a pocket in, from which a straight line leads down
    to its approach (None: neither has one). `wanted` (the put's nest's twin) if it can, else the one
    sooner down, the line's torso included: the twin sooner above the pocket alone can leave the
    line down out of the arm's reach (the fetch from the hotel's left pocket then lowered the torso
    0.14 m, 2.4 s, where the other twin's arm alone goes straight down)."""
    T_above, T_below = above_below
    ranked = []
    for flip in (False, True):
        joints = planning.plan_joint_move(arm, seed, twin_pose(T_above, flip))
        if joints is None:
            continue
        above = {**seed, **joints}
        for torso in (False, True):  # as straight_move plans it: the arm alone if it can
            line = planning.plan_line(arm, above, twin_pose(T_below, flip), use_torso=torso)
            if isinstance(line, list):
                seconds = move_s(seed, joints) + move_s(above, line[-1])
                ranked.append((wanted is not None and flip != wanted, seconds, flip))
                break
    return min(ranked)[2] if ranked else None
