"""play_motion Tuck from over the onboard hotel rises to the carry height before it folds the arm;
from over a bench the tool first goes level back to the bench's front line.

Why: folding in joint space from the hotel's approach pose swings the finger pads over the front
edge of the bench the robot works at (random layout 91089; tests/tiago_description/test_fold_sweep.py
has the geometry). A recording hardware stands in for the robot: it records the trajectories sent.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest
from labware_interfaces.action import PlayMotion

from robot_port.types import JointTrajectory
from tiago_description import robot_model as rm
from tiago_description.kinematics import RobotKinematics
from tiago_description.motion_library import load_motions
from tiago_description.transforms import make_transform
from tiago_skills.behaviours import BENCH_FRONT_X, OPEN_FINGER_REACH, WORKING_CLEARANCE, RobotBehaviours
from tiago_skills.goal_run import GoalRun

ARM = "right"


class RecordingHardware:
    """Joint readings and the trajectories sent, in order; a trajectory ends where it was sent."""

    def __init__(self, joints: dict[str, float]) -> None:
        self.joints = dict(joints)
        self.started: list[tuple[str, dict[str, float]]] = []

    def now(self) -> float:
        return 0.0

    def joint_positions(self) -> dict[str, float]:
        return dict(self.joints)

    def follow_joint_trajectory(self, trajectory: JointTrajectory) -> Any:
        self.started.append((trajectory.name, dict(trajectory.points[-1])))
        self.joints.update(trajectory.points[-1])
        return SimpleNamespace(
            name=trajectory.name, done=True, success=True, error_code="", message="done",
            progress=1.0, phase="done", remaining_s=0.0, result={}, wait=lambda _s: True, cancel=lambda: None,
        )  # fmt: skip


def benchtop_joints() -> dict[str, float]:
    """The arm, torso and head where the "Benchtop" motion leaves them."""
    joints: dict[str, float] = {}
    for frame in load_motions().frames_for("Benchtop", ARM):
        joints.update(frame)
    return joints


def goal_run(hardware: RecordingHardware) -> GoalRun:
    handle = SimpleNamespace(is_cancel_requested=False, publish_feedback=lambda _message: None)
    return GoalRun(handle, PlayMotion.Feedback, hardware)


def behaviours(seed: int | None = None) -> RobotBehaviours:
    return RobotBehaviours(
        poi_pose=lambda _name: None,
        poi_names=list,
        dock_poi=lambda: "dock_approach",
        hotel_slots=2,
        motions=load_motions(),
        speed_scale=lambda: 1.0,
        seed=seed,
    )


def joints_over_hotel_slot(slot: int) -> dict[str, float]:
    """The arm at the approach of a hotel slot (where GetLabware's retract leaves it), gripper open."""
    kinematics, motions = RobotKinematics(), load_motions()
    seed = benchtop_joints()
    seed.update({"torso_lift_joint": 0.25, **{n: rm.FINGER_TRAVEL for n in rm.finger_joint_names(ARM)}})
    T = kinematics.forward({}, f"hotel_slot_{slot}") @ motions.hotel.T_slot_grasp(approach=True)
    result = kinematics.inverse(ARM, T, seed, use_torso=False, restarts=40)
    assert result.success
    return {**seed, **result.joint_positions}


@pytest.mark.parametrize("slot", [1, 2])
def test_tuck_over_the_hotel_rises_to_the_carry_height_first(slot: int) -> None:
    robot = behaviours()
    hardware = RecordingHardware(joints_over_hotel_slot(slot))
    robot.play_motion(goal_run(hardware), SimpleNamespace(arm=ARM, motion_name="Tuck", hotel_slot=0))
    (kind, carry_joints), *rest = hardware.started
    expected = robot.hotel_grasp_pose(slot, approach=True)[2, 3] + robot.motions.hotel.carry_height_m
    assert kind == "move_tool"
    assert robot.planning.tool_pose(ARM, {**hardware.joints, **carry_joints})[2, 3] == pytest.approx(
        expected, abs=1e-3
    )
    assert [kind for kind, _ in rest] == ["move_joints"] * len(robot.motions.frames_for("Tuck", ARM))


def test_tuck_elsewhere_folds_straight_away() -> None:
    robot = behaviours()
    bench = benchtop_joints()
    hardware = RecordingHardware(bench)
    robot.play_motion(goal_run(hardware), SimpleNamespace(arm=ARM, motion_name="Tuck", hotel_slot=0))
    assert [kind for kind, _ in hardware.started] == ["move_joints"]


def joints_over_a_nest(x: float, y: float, z: float) -> dict[str, float]:
    """The arm top-down over a nest ahead of the base (a nest's approach pose), gripper open."""
    kinematics, motions = RobotKinematics(), load_motions()
    seed = benchtop_joints()
    seed.update({n: rm.FINGER_TRAVEL for n in rm.finger_joint_names(ARM)})
    T = make_transform((x, y, z)) @ motions.hotel.T_slot_grasp(approach=False)
    result = kinematics.inverse(ARM, T, seed, use_torso=True, restarts=40)
    assert result.success
    return {**seed, **result.joint_positions}


@pytest.mark.parametrize("motion", ["Tuck", "NestApproach"])
def test_leaving_a_bench_goes_straight_back_to_its_front_line_first(motion: str) -> None:
    """Over a standing bench (nest approach 0.95 m high, 0.49 m ahead) the tool first moves level to
    BENCH_FRONT_X, in front of every bench edge the loader allows, then folds or goes to the hotel."""
    robot = behaviours()
    hardware = RecordingHardware(joints_over_a_nest(0.49, -0.20, 0.95))
    robot.play_motion(goal_run(hardware), SimpleNamespace(arm=ARM, motion_name=motion, hotel_slot=1))
    (kind, back), *_rest = hardware.started
    assert kind in ("move_tool", "move_joints")  # straight if the arm can, else one short joint move
    start = robot.planning.tool_pose(ARM, joints_over_a_nest(0.49, -0.20, 0.95))
    front = robot.planning.tool_pose(ARM, {**joints_over_a_nest(0.49, -0.20, 0.95), **back})
    assert front[0, 3] == pytest.approx(BENCH_FRONT_X, abs=1e-3)
    assert front[1:3, 3] == pytest.approx(start[1:3, 3], abs=1e-3)  # level, straight back
    assert BENCH_FRONT_X + OPEN_FINGER_REACH < WORKING_CLEARANCE  # the open fingers clear the edge


def test_towards_a_nest_higher_than_the_tool_the_tool_rises_in_front_of_the_bench_first() -> None:
    robot = behaviours()
    bench = benchtop_joints()
    hardware = RecordingHardware(bench)
    start = robot.planning.tool_pose(ARM, bench)
    target = make_transform((0.49, -0.20, 0.95)) @ robot.motions.hotel.T_slot_grasp(approach=False)
    used = robot.rise_before_bench(goal_run(hardware), ARM, target, 0.1)
    assert used > 0.1
    ((kind, up),) = hardware.started
    risen = robot.planning.tool_pose(ARM, {**bench, **up})
    assert kind == "move_tool" and risen[2, 3] == pytest.approx(target[2, 3], abs=1e-3)
    assert risen[:2, 3] == pytest.approx(start[:2, 3], abs=1e-3)  # straight up where it stood
    low = make_transform((0.49, -0.20, 0.80)) @ robot.motions.hotel.T_slot_grasp(approach=False)
    assert robot.rise_before_bench(goal_run(hardware), ARM, low, 0.1) == 0.1  # a sitting bench: nothing
