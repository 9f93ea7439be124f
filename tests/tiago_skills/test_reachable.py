"""At the edge of the arm's reach, the first of a target's fallbacks the arm reaches, with the real IK.

Why: a target computed for an arm working at the edge of its reach can lie millimetres beyond it,
where a fallback lies within. A measured place (the place correction's shift) beyond reach falls
back to the place the marker gives, which the approach reached (random layout 200084: IK_FAILED,
then delivered as marked); a nest approach at the station's approach height falls back to lower
ones, down to the least that keeps a held plate over a neighbour's tallest labware. The edge is
found here with the robot model's own IK, so the tests follow the model.
"""

from __future__ import annotations

import numpy as np
import pytest

from lab_description.station_placement import APPROACH_CLEARANCE_M
from lab_description.world import load_world
from tests.tiago_sim.sim_node.test_fold_from_hotel import behaviours, benchtop_joints
from tiago_description import transforms as tf
from tiago_description.motion_library import load_motions
from tiago_skills.behaviours import RobotBehaviours
from tiago_skills.goal_run import ActionAbort
from tiago_skills.marker_motion import MarkerMotionBehaviour
from tiago_skills.reachable import first_reachable

ARM = "right"
HOTEL = load_motions().hotel
GRASP = HOTEL.T_slot_grasp(approach=False, releasing=True)


def place(x: float, z: float = 0.744) -> np.ndarray:
    """The grasp pose over a nest x m ahead, 1.6 cm right of the centre line, z m high."""
    return tf.make_transform((x, -0.016, z)) @ GRASP


@pytest.fixture(scope="module")
def holding() -> RobotBehaviours:
    robot = behaviours(seed=0)
    robot.holding[ARM], robot.grasp_flipped[ARM] = True, False  # the twin the plate was taken with
    return robot


def reached(robot: RobotBehaviours, grasp: np.ndarray) -> bool:
    try:
        robot.grasp_twin(ARM, grasp, benchtop_joints())
    except ActionAbort:
        return False
    return True


@pytest.fixture(scope="module")
def edge(holding: RobotBehaviours) -> tuple[float, float]:
    """The last reachable and the first unreachable x along the line, 5 mm apart."""
    last = None
    for x in np.arange(0.45, 0.85, 0.005):
        if not reached(holding, place(float(x))):
            assert last is not None, "nothing on the line is reachable"
            return last, float(x)
        last = float(x)
    pytest.fail("the whole line is reachable: no edge to test")


def test_a_target_beyond_reach_falls_back_to_the_first_the_arm_reaches(
    holding: RobotBehaviours, edge: tuple[float, float]
) -> None:
    reachable, beyond = edge
    grasps = [place(beyond + 0.01), place(beyond), place(reachable), place(reachable - 0.005)]
    target, index = first_reachable(holding, ARM, grasps, benchtop_joints())
    assert index == 2
    np.testing.assert_allclose(target[:3, 3], place(reachable)[:3, 3], atol=1e-9)


def test_a_reachable_target_is_kept(holding: RobotBehaviours, edge: tuple[float, float]) -> None:
    reachable, _beyond = edge
    grasps = [place(reachable), place(reachable - 0.005)]
    target, index = first_reachable(holding, ARM, grasps, benchtop_joints())
    assert index == 0
    np.testing.assert_allclose(target[:3, 3], place(reachable)[:3, 3], atol=1e-9)


def test_with_no_target_reached_the_first_is_named(
    holding: RobotBehaviours, edge: tuple[float, float]
) -> None:
    _reachable, beyond = edge
    with pytest.raises(ActionAbort, match=f"cannot reach .*{beyond:.3f}"):
        first_reachable(holding, ARM, [place(beyond), place(beyond + 0.01)], benchtop_joints())


def test_a_nest_approach_lowers_to_what_the_arm_reaches_but_never_below_a_neighbours_plate(
    holding: RobotBehaviours,
) -> None:
    """The heights tried above a nest: the station's first, then lower ones, none below the tallest
    labware type plus the clearance; over a nest whose station height the arm does not reach, one of
    the lower ones is reached."""
    world = load_world()
    motion = MarkerMotionBehaviour(world, holding, HOTEL)
    station = world.stations[0]
    heights = motion._approach_heights(station)
    tallest = max(t.height for t in world.labware_types.values())
    assert heights[0] == station.approach_height and heights == sorted(heights, reverse=True)
    assert heights[-1] >= tallest + APPROACH_CLEARANCE_M - 1e-9 and len(heights) > 1
    x = 0.55
    nest_z = next(
        z
        for z in np.arange(0.70, 1.00, 0.005)
        if not reached(holding, place(x, z + heights[0])) and reached(holding, place(x, z + heights[-1]))
    )
    grasps = [place(x, nest_z + height) for height in heights]
    _target, index = first_reachable(holding, ARM, grasps, benchtop_joints())
    assert index > 0
