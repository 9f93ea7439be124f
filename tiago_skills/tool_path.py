"""Joint waypoints that move a grasping frame along a straight line (or straight to a pose), by IK.

Why apart from the Simulation: this is pure kinematics on the robot model (pinocchio), no
physics; the robot's joint-trajectory controllers time the waypoints (tool_trajectory). Safe on any thread
that owns the RobotKinematics it is given.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from robot_port.types import JointTrajectory
from tiago_description import transforms as tf
from tiago_description.kinematics import RobotKinematics

STRAIGHT_STEP = 0.01  # m between IK waypoints
MAX_WAYPOINT_JUMP = 0.25  # rad between consecutive IK waypoints


def plan_tool_path(
    kinematics: RobotKinematics,
    rng: np.random.Generator,
    arm: str,
    current: dict[str, float],
    T_base_grasp: np.ndarray,
    straight_line: bool,
    use_torso: bool,
) -> list[dict[str, float]] | str:
    """Joint positions per waypoint from ``current`` to ``T_base_grasp`` (grasping frame in
    base_footprint), or the reason there are none (an unreachable waypoint, a joint jump)."""
    T_start = kinematics.forward(current, f"gripper_{arm}_grasping_frame")
    T_goal = np.asarray(T_base_grasp, dtype=float)
    waypoints = _straight_path(T_start, T_goal) if straight_line else [T_goal]
    solutions: list[dict[str, float]] = []
    seed = dict(current)
    for index, T_waypoint in enumerate(waypoints):
        restarts = 30 if (index == 0 and not straight_line) else 3
        result = kinematics.inverse(
            arm,
            T_waypoint,
            seed,
            use_torso=use_torso,
            restarts=restarts,
            seed=int(rng.integers(1 << 30)),
        )
        jump = max((abs(result.joint_positions[n] - seed[n]) for n in result.joint_positions), default=0.0)
        if straight_line and (not result.success or jump > MAX_WAYPOINT_JUMP):
            # near a joint limit the seeded solve can stall: creep there in small, seeded steps
            T_previous = waypoints[index - 1] if index else T_start
            result = _creep(kinematics, arm, T_previous, T_waypoint, seed, use_torso) or result
            jump = max(
                (abs(result.joint_positions[n] - seed[n]) for n in result.joint_positions), default=0.0
            )
        if not result.success or (straight_line and jump > MAX_WAYPOINT_JUMP):
            why = "unreachable" if not result.success else f"joint jump {jump:.2f} rad"
            return f"waypoint {index + 1}/{len(waypoints)} {why}"
        solutions.append(result.joint_positions)
        seed.update(result.joint_positions)
    return solutions


def tool_trajectory(
    waypoints: list[dict[str, float]], tool_speed: float, straight_line: bool = True
) -> JointTrajectory:
    """The joint trajectory through planned waypoints: along a straight line one waypoint per
    STRAIGHT_STEP, each segment no faster than `tool_speed` (m/s) moves the tool."""
    segment_s = STRAIGHT_STEP / max(tool_speed, 1e-3) if straight_line else 0.0
    return JointTrajectory(tuple(waypoints), 1.0, min_segment_s=segment_s, name="move_tool")


def _creep(
    kinematics: RobotKinematics,
    arm: str,
    T_from: np.ndarray,
    T_to: np.ndarray,
    seed: dict[str, float],
    use_torso: bool = True,
):
    """IK for T_to reached from T_from in seeded sub-steps (no random restarts), or None."""
    here = dict(seed)
    result = None
    for T_sub in _straight_path(T_from, T_to, step=STRAIGHT_STEP / 5):
        result = kinematics.inverse(arm, T_sub, here, use_torso=use_torso, restarts=0, max_iterations=400)
        if not result.success:
            return None
        here.update(result.joint_positions)
    return result


def _straight_path(T_start: np.ndarray, T_goal: np.ndarray, step: float = STRAIGHT_STEP) -> list[np.ndarray]:
    """Poses along the straight line (and the shortest rotation) from start to goal, goal last."""
    distance = float(np.linalg.norm(T_goal[:3, 3] - T_start[:3, 3]))
    angle = tf.rotation_angle(T_start[:3, :3], T_goal[:3, :3])
    count = max(1, math.ceil(distance / step), math.ceil(angle / (5 * step)))
    relative = T_start[:3, :3].T @ T_goal[:3, :3]
    axis_angle = _log_rotation(relative)
    poses = []
    for i in range(1, count + 1):
        s = i / count
        pose = np.eye(4)
        pose[:3, 3] = T_start[:3, 3] + s * (T_goal[:3, 3] - T_start[:3, 3])
        pose[:3, :3] = T_start[:3, :3] @ _exp_rotation(s * axis_angle)
        poses.append(pose)
    return poses


def _log_rotation(rotation: np.ndarray) -> np.ndarray:
    return np.asarray(pin.log3(rotation))


def _exp_rotation(vector: np.ndarray) -> np.ndarray:
    return np.asarray(pin.exp3(vector))
