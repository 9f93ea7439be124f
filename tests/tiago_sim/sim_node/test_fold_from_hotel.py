"""play_motion Tuck from over the onboard hotel rises to the carry height before it folds the arm.

Why: folding in joint space from the hotel's approach pose swings the finger pads over the front
edge of the bench the robot works at (random layout 91089; tests/tiago_sim/robot/test_fold_sweep.py
has the geometry). A fake run stands in for the sim thread: it records the motions asked for.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from tiago_sim.robot import robot_model as rm
from tiago_sim.robot.kinematics import RobotKinematics
from tiago_sim.robot.motion_library import load_motions
from tiago_sim.sim_node.behaviours import RobotBehaviours

ARM = "right"


class FakeSim:
    """Joint readings and the motions started, in order; a motion ends where it was sent."""

    def __init__(self, joints: dict[str, float]) -> None:
        self.joints = dict(joints)
        self.started: list[tuple[str, Any]] = []

    def joint_positions(self) -> dict[str, float]:
        return dict(self.joints)

    def move_tool(self, arm: str, T_base_grasp: np.ndarray, *_args: Any) -> None:
        self.started.append(("move_tool", np.array(T_base_grasp)))

    def move_joints(self, targets: dict[str, float], _speed: float) -> None:
        self.started.append(("move_joints", dict(targets)))
        self.joints.update(targets)


class FakeRun:
    def __init__(self, sim: FakeSim) -> None:
        self._sim = sim

    def sim(self, job: Any) -> Any:
        return job(self._sim)

    def run_motion(self, start: Any, *, span: tuple[float, float] = (0.0, 1.0)) -> Any:
        return start(self._sim)


def behaviours() -> RobotBehaviours:
    return RobotBehaviours(
        poi_pose=lambda _name: None,
        poi_names=list,
        dock_poi=lambda: "dock_approach",
        hotel_slots=2,
        motions=load_motions(),
        speed_scale=lambda: 1.0,
        navigation=SimpleNamespace(),
    )


def joints_over_hotel_slot(slot: int) -> dict[str, float]:
    """The arm at the approach of a hotel slot (where GetLabware's retract leaves it), gripper open."""
    kinematics, motions = RobotKinematics(), load_motions()
    seed: dict[str, float] = {}
    for frame in motions.frames_for("Benchtop", ARM):
        seed.update(frame)
    seed.update({"torso_lift_joint": 0.25, **{n: rm.FINGER_TRAVEL for n in rm.finger_joint_names(ARM)}})
    T = kinematics.forward({}, f"hotel_slot_{slot}") @ motions.hotel.T_slot_grasp(approach=True)
    result = kinematics.inverse(ARM, T, seed, use_torso=False, restarts=40)
    assert result.success
    return {**seed, **result.joint_positions}


@pytest.mark.parametrize("slot", [1, 2])
def test_tuck_over_the_hotel_rises_to_the_carry_height_first(slot: int) -> None:
    robot = behaviours()
    sim = FakeSim(joints_over_hotel_slot(slot))
    robot.play_motion(FakeRun(sim), SimpleNamespace(arm=ARM, motion_name="Tuck", hotel_slot=0))
    (kind, T_carry), *rest = sim.started
    expected = robot.hotel_grasp_pose(slot, approach=True)[2, 3] + robot.motions.hotel.carry_height_m
    assert kind == "move_tool" and T_carry[2, 3] == pytest.approx(expected)
    assert [kind for kind, _ in rest] == ["move_joints"] * len(robot.motions.frames_for("Tuck", ARM))


def test_tuck_elsewhere_folds_straight_away() -> None:
    robot = behaviours()
    bench: dict[str, float] = {}
    for frame in robot.motions.frames_for("Benchtop", ARM):
        bench.update(frame)
    sim = FakeSim(bench)
    robot.play_motion(FakeRun(sim), SimpleNamespace(arm=ARM, motion_name="Tuck", hotel_slot=0))
    assert [kind for kind, _ in sim.started] == ["move_joints"]
