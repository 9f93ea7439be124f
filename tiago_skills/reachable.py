"""The first of several grasp poses the arm reaches: a target at the edge of reach, and its fallbacks.

Lives on the calling goal's thread (the arm planning's IK is the caller's).
"""

from __future__ import annotations

import numpy as np

from tiago_skills.behaviours import RobotBehaviours
from tiago_skills.goal_run import ActionAbort


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
