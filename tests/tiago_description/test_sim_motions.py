"""Arm, torso and head motions in physics: URDF speed limits hold, refusals carry the right codes."""

from __future__ import annotations

import numpy as np
import pytest

from lab_description.world import load_world
from tests.helpers.tool_moves import move_tool
from tiago_description import robot_model as rm
from tiago_description.kinematics import top_down_grasp
from tiago_sim.physics.simulation import Simulation


@pytest.fixture(scope="module")
def sim():
    simulation = Simulation(load_world(), seed=4)
    yield simulation
    simulation.close()


def test_joint_motion_reaches_its_goal_within_the_velocity_limits(sim):
    arm = rm.arm_joint_names("right")
    goal = {
        "torso_lift_joint": 0.30,
        "head_2_joint": -0.5,
        **dict(zip(arm, (0.6, 0.2, 0.5, 1.2, 0.3, -0.4, 0.8), strict=True)),
    }
    names = list(goal)
    motion = sim.move_joints(goal)
    peak = np.zeros(len(names))
    while not motion.done:
        sim.step()
        peak = np.maximum(peak, np.abs(sim.robot.joint_velocities(names)))
    assert motion.success, motion.message
    reached = sim.joint_positions()
    for name in names:
        assert reached[name] == pytest.approx(goal[name], abs=0.01), name
    limits = np.array([sim.robot.limits[n][2] for n in names])
    assert np.all(peak <= limits * 1.05), dict(zip(names, peak / limits, strict=True))
    torso = names.index("torso_lift_joint")
    assert peak[torso] == pytest.approx(rm.TORSO_LIFT_SPEED, rel=0.1)  # the slowest joint sets the pace


def test_half_speed_takes_about_twice_as_long(sim):
    arm = rm.arm_joint_names("right")
    durations = []
    assert sim.run(sim.move_joints({arm[0]: 0.2})).success
    for scale, value in ((1.0, 0.8), (0.5, 0.2)):  # the same 0.6 rad, there and back
        motion = sim.move_joints({arm[0]: value}, speed_scale=scale)
        start = sim.sim_time
        sim.run(motion)
        assert motion.success
        durations.append(sim.sim_time - start)
    assert durations[1] == pytest.approx(2 * durations[0], rel=0.25)


def test_refusals_carry_error_codes(sim):
    unreachable = move_tool(sim, "right", top_down_grasp(np.array([1.5, 0.0, 0.8]), 0.0), straight_line=False)
    assert unreachable.done and unreachable.error_code == "IK_FAILED"
    assert move_tool(sim, "middle", np.eye(4)).error_code == "BAD_GOAL"
    assert sim.move_joints({"no_such_joint": 1.0}).error_code == "BAD_GOAL"
    first = sim.move_joints({"head_1_joint": 0.5})
    second = sim.move_joints({"head_1_joint": -0.5})
    assert not first.done and second.done and second.error_code == "BUSY"
    first.cancel()
    sim.run(first)
    assert first.error_code == "CANCELED" and not sim.busy()
