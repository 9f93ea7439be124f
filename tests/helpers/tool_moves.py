"""Tool moves on a bare Simulation, planned as the skills plan them (tiago_skills.tool_path) and
run by the simulated joint-trajectory controllers, for physics tests that script a robot by hand.

Why a helper: the Simulation plays only the hardware; a straight tool line is robot software. The
tests that grasp and place without the ROS node plan exactly what the skills would send.
"""

from __future__ import annotations

import weakref

import numpy as np

from robot_port.types import ARM_SIDES
from tiago_description.kinematics import RobotKinematics
from tiago_sim.physics.motion import FailedMotion, Motion
from tiago_sim.physics.simulation import Simulation
from tiago_skills.tool_path import plan_tool_path, tool_trajectory

TOOL_SPEED = 0.08  # m/s, the skills' speed into a pocket
KINEMATICS = RobotKinematics()  # the robot model the skills plan with
# IK restart seeds per Simulation, so a test's moves do not depend on the tests run before it
_RNGS: weakref.WeakKeyDictionary[Simulation, np.random.Generator] = weakref.WeakKeyDictionary()


def move_tool(
    sim: Simulation,
    arm: str,
    T_base_grasp: np.ndarray,
    straight_line: bool = True,
    tool_speed: float = TOOL_SPEED,
    use_torso: bool = True,
) -> Motion:
    """Grasping frame of ``arm`` to a pose in base_footprint (straight when asked), started on `sim`."""
    if arm not in ARM_SIDES:
        return FailedMotion("move_tool", "BAD_GOAL", f"unknown arm {arm!r}")
    rng = _RNGS.setdefault(sim, np.random.default_rng(0))
    planned = plan_tool_path(
        KINEMATICS, rng, arm, sim.joint_positions(), T_base_grasp, straight_line, use_torso
    )
    if isinstance(planned, str):
        return FailedMotion("move_tool", "IK_FAILED", planned)
    return sim.execute_trajectory(tool_trajectory(planned, tool_speed, straight_line))
