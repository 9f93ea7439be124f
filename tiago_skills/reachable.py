"""The first of several grasp poses the arm reaches: a target at the edge of reach, and its fallbacks;
and the twin of the top-down grasp a put's nest needs, where only one reaches.

Lives on the calling goal's thread (the arm planning's IK is the caller's).
"""

from __future__ import annotations

import logging

import numpy as np

from tiago_description import transforms as tf
from tiago_description.motion_library import HotelGrasp
from tiago_skills.behaviours import RobotBehaviours
from tiago_skills.goal_run import ActionAbort
from tiago_skills.grasp_twins import FLIP_ABOUT_APPROACH

log = logging.getLogger(__name__)
TWINS = {False: "nominal", True: "turned"}


def first_reachable(
    behaviours: RobotBehaviours, arm: str, grasps: list[np.ndarray], seed: dict[str, float]
) -> tuple[np.ndarray, int]:
    """The grasp pose (the twin the arm holds the plate with, or the nearer of the twins) for the
    first of `grasps` the arm reaches, and its index; IK_FAILED naming the first if it reaches none.

    Why: a target computed for an arm working at the edge of its reach can lie millimetres beyond it,
    where a fallback the approach can also take lies within: a measured place beyond reach, with the
    place the marker gives (random layout 200084); a nest approach at the station's approach height,
    with lower ones down to the least that clears a neighbour's plate (nests 0.95 to 0.97 m high)."""
    failure: ActionAbort | None = None
    for index, T_base_grasp in enumerate(grasps):
        try:
            return behaviours.grasp_twin(arm, T_base_grasp, seed), index
        except ActionAbort as unreachable:
            failure = failure or unreachable
    assert failure is not None, "no grasp pose given"
    raise failure


def twin_reaching(
    behaviours: RobotBehaviours, arm: str, pose_sets: list[list[np.ndarray]], seed: dict[str, float]
) -> bool | None:
    """The one twin (False: the poses as given, True: turned half about the approach) with which the
    arm reaches a pose of every set, or None when both or neither do.

    Why: a plate fetched from the hotel goes down with the twin it was fetched with (its orientation
    is kept), and at a nest near the edge of reach only one twin may reach: fetched by the least
    joint travel, the plate came with the other, and the put failed (IK_FAILED, random layout
    205042)."""
    reaching = [
        flip
        for flip in (False, True)
        if all(
            any(
                behaviours.planning.solve_ik(arm, T @ FLIP_ABOUT_APPROACH if flip else T, seed) is not None
                for T in poses
            )
            for poses in pose_sets
        )
    ]
    return reaching[0] if len(reaching) == 1 else None


def put_twin(
    behaviours: RobotBehaviours,
    arm: str,
    T_base_site: np.ndarray,
    approach_heights: list[float],
    grasp: HotelGrasp,
    seed: dict[str, float],
) -> bool | None:
    """The one twin with which the arm reaches a nest's approach (at one of `approach_heights`) and
    its place, or None when both or neither do (`twin_reaching`)."""
    over = [
        T_base_site @ tf.make_transform((0.0, 0.0, h)) @ grasp.T_slot_grasp(False) for h in approach_heights
    ]
    place = T_base_site @ grasp.T_slot_grasp(False, releasing=True)
    wanted = twin_reaching(behaviours, arm, [[place], over], seed)  # the place first: one pose
    if wanted is not None:
        log.info("only the %s twin reaches the put's nest: the plate is fetched with it", TWINS[wanted])
    return wanted
