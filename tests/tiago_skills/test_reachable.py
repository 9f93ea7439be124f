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
from tiago_skills.grasp_twins import FLIP_ABOUT_APPROACH
from tiago_skills.marker_motion import MarkerMotionBehaviour
from tiago_skills.reachable import first_reachable, put_twin

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


def nest(x: float, y: float, z: float = 0.732) -> np.ndarray:
    """A nest x m ahead and y m to the left, its long side across the base (as a bench ahead has it)."""
    return tf.from_planar(x, y, -np.pi / 2, z)


@pytest.fixture(scope="module")
def empty_handed() -> RobotBehaviours:
    return behaviours(seed=0)


def test_a_put_nest_only_one_twin_reaches_asks_for_that_twin(empty_handed: RobotBehaviours) -> None:
    """Near the edge of reach one twin may reach a nest and the other not (random layout 205042: the
    plate came from the hotel with the other one, IK_FAILED); the put's nest then names its twin, and
    a nest well within reach names none."""
    seed, heights = benchtop_joints(), [0.09]
    assert put_twin(empty_handed, ARM, nest(0.50, -0.20), heights, HOTEL, seed) is None
    for x in np.arange(0.58, 0.70, 0.005):
        site = nest(float(x), -0.033)
        wanted = put_twin(empty_handed, ARM, site, heights, HOTEL, seed)
        if wanted is None:
            continue
        poses = (site @ tf.make_transform((0.0, 0.0, 0.09)) @ HOTEL.T_slot_grasp(False), site @ GRASP)
        reaches = {
            flip: all(empty_handed.planning.solve_ik(ARM, pose @ turn, seed) for pose in poses)
            for flip, turn in ((False, np.eye(4)), (True, FLIP_ABOUT_APPROACH))
        }
        assert reaches[wanted] and not reaches[not wanted]
        return
    pytest.fail("no nest on the line that only one twin reaches: the model's reach moved")


def test_the_hotel_fetch_takes_the_twin_the_put_needs(empty_handed: RobotBehaviours) -> None:
    """Empty-handed, the twin wanted wins over the one of least travel wherever both reach."""
    fetch = empty_handed.hotel_grasp_pose(1, approach=False)
    seed = benchtop_joints()
    try:
        for wanted in (False, True):
            empty_handed.twin_wanted[ARM] = wanted
            chosen = empty_handed.grasp_twin(ARM, fetch, seed)
            expected = fetch @ FLIP_ABOUT_APPROACH if wanted else fetch
            np.testing.assert_allclose(chosen, expected, atol=1e-9)
            assert empty_handed.grasp_flipped[ARM] is wanted
    finally:
        empty_handed.twin_wanted.clear()


@pytest.mark.parametrize(
    ("flip", "x", "y", "z"),
    [(False, 0.50, -0.10, 0.96), (False, 0.57, -0.23, 0.93), (True, 0.47, -0.10, 0.96)],
)
def test_a_route_finds_a_joint_goal_wherever_the_reach_check_reached(
    empty_handed: RobotBehaviours, flip: bool, x: float, y: float, z: float
) -> None:
    """At the edge of reach, where a few random IK starts find no solution but the reach check's
    thorough solve does (a route to an approach 0.97 m high found no way: IK_FAILED)."""
    target = nest(x, y, z) @ HOTEL.T_slot_grasp(False) @ (FLIP_ABOUT_APPROACH if flip else np.eye(4))
    seed = benchtop_joints()
    assert empty_handed.planning.solve_ik(ARM, target, seed) is not None, "the model's reach moved"
    goals = empty_handed.planning.joint_move_goals(ARM, seed, target)
    assert goals, "the route has no joint-space goal for a target the reach check reached"
    for goal in goals:
        reached = empty_handed.planning.tool_pose(ARM, {**seed, **goal})
        np.testing.assert_allclose(reached[:3, 3], target[:3, 3], atol=1e-3)
