"""A measured place beyond the arm's reach falls back to the place the marker gives, with the real IK.

Why: at a nest on the edge of the right arm's reach, the place correction's shift of a few
millimetres can leave the arm's reach (random layout 200084: IK_FAILED), while the place the marker
alone gives, which the approach reached, delivers. The edge is found here with the robot model's own
IK, along a line ahead of the base at a nest's height, so the test follows the model.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.tiago_sim.sim_node.test_fold_from_hotel import behaviours, benchtop_joints
from tiago_description import transforms as tf
from tiago_description.motion_library import load_motions
from tiago_skills.behaviours import RobotBehaviours
from tiago_skills.goal_run import ActionAbort
from tiago_skills.marker_motion import reachable_place

ARM = "right"
GRASP = load_motions().hotel.T_slot_grasp(approach=False, releasing=True)


def place(x: float) -> np.ndarray:
    """The grasp pose of a place into a nest x m ahead, 1.6 cm right of the centre line, 0.744 m high."""
    return tf.make_transform((x, -0.016, 0.744)) @ GRASP


@pytest.fixture(scope="module")
def holding() -> RobotBehaviours:
    robot = behaviours(seed=0)
    robot.holding[ARM], robot.grasp_flipped[ARM] = True, False  # the twin the plate was taken with
    return robot


@pytest.fixture(scope="module")
def edge(holding: RobotBehaviours) -> tuple[float, float]:
    """The last reachable and the first unreachable x along the line, 5 mm apart."""
    last = None
    for x in np.arange(0.45, 0.85, 0.005):
        try:
            holding.grasp_twin(ARM, place(float(x)), benchtop_joints())
        except ActionAbort:
            assert last is not None, "nothing on the line is reachable"
            return last, float(x)
        last = float(x)
    pytest.fail("the whole line is reachable: no edge to test")


def test_a_measured_place_beyond_reach_falls_back_to_the_place_as_marked(
    holding: RobotBehaviours, edge: tuple[float, float]
) -> None:
    reachable, beyond = edge
    target, fell_back = reachable_place(holding, ARM, place(beyond), place(reachable), benchtop_joints())
    assert fell_back
    np.testing.assert_allclose(target[:3, 3], place(reachable)[:3, 3], atol=1e-9)


def test_a_reachable_measured_place_is_kept(holding: RobotBehaviours, edge: tuple[float, float]) -> None:
    reachable, _beyond = edge
    nearer = place(reachable - 0.005)
    target, fell_back = reachable_place(holding, ARM, place(reachable), nearer, benchtop_joints())
    assert not fell_back
    np.testing.assert_allclose(target[:3, 3], place(reachable)[:3, 3], atol=1e-9)


def test_with_neither_place_reached_the_arm_cannot_reach(
    holding: RobotBehaviours, edge: tuple[float, float]
) -> None:
    _reachable, beyond = edge
    for as_marked in (place(beyond + 0.01), None):
        with pytest.raises(ActionAbort, match="cannot reach"):
            reachable_place(holding, ARM, place(beyond), as_marked, benchtop_joints())
