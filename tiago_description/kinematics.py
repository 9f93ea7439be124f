"""Forward and inverse kinematics of our TIAGo++ with pinocchio, from the same URDF the simulation loads.

Why here and not in PyBullet: the robot software (marker motion, sequencer) must work from joint
readings alone, as on the real robot, so FK/IK never look at simulator link states.
All poses are ``T_base_frame``: the frame's pose in ``base_footprint``. Pure computation; safe
to use from any thread as long as one ``RobotKinematics`` is not shared between threads.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import pinocchio as pin

from tiago_description import robot_model
from tiago_description import transforms as tf

log = logging.getLogger(__name__)

CAMERA_FRAME = "head_front_camera_rgb_optical_frame"
IK_DAMPING = 1e-3
IK_POSITION_TOLERANCE = 5e-4  # m
IK_ORIENTATION_TOLERANCE = 2e-3  # rad
IK_STALL_ITERATIONS = 15  # a solve ends when its error has not dropped by IK_STALL_PROGRESS in this many
IK_STALL_PROGRESS = 1e-6  # m (+ 0.1 m per rad)
DISTINCT_SOLUTION_RAD = 0.1  # two IK solutions this close on every joint count as one


@dataclass(frozen=True)
class IkResult:
    """Outcome of one IK request; ``joint_positions`` holds only the joints IK was allowed to move."""

    success: bool
    joint_positions: dict[str, float] = field(default_factory=dict)
    position_error_m: float = float("inf")
    orientation_error_rad: float = float("inf")
    attempts: int = 0


class RobotKinematics:
    """pinocchio model of the whole robot with name-based joint access."""

    def __init__(self) -> None:
        self.model = pin.buildModelFromUrdf(str(robot_model.urdf_path()))
        self.data = self.model.createData()
        self.lower = self.model.lowerPositionLimit.copy()
        self.upper = self.model.upperPositionLimit.copy()

    def _q(self, joint_positions: Mapping[str, float]) -> np.ndarray:
        q = pin.neutral(self.model)
        for name, value in joint_positions.items():
            if not self.model.existJointName(name):
                continue
            joint = self.model.joints[self.model.getJointId(name)]
            if joint.nq == 1:
                q[joint.idx_q] = value
            else:  # continuous joint stored as (cos, sin)
                q[joint.idx_q : joint.idx_q + 2] = (np.cos(value), np.sin(value))
        return q

    def configuration(self, joint_positions: Mapping[str, float]) -> np.ndarray:
        """pinocchio's q for the named joint positions; joints not given are taken at zero."""
        return self._q(joint_positions)

    def forward(self, joint_positions: Mapping[str, float], frame: str) -> np.ndarray:
        """4x4 pose of ``frame`` in base_footprint; joints not given are taken at zero."""
        return self._frame_pose(self._q(joint_positions), frame)

    def _frame_pose(self, q: np.ndarray, frame: str) -> np.ndarray:
        frame_id = self.model.getFrameId(frame)
        if frame_id >= len(self.model.frames):
            raise KeyError(f"unknown frame {frame!r}")
        pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[frame_id].homogeneous.copy()

    def joint_index(self, name: str) -> int:
        """Index in q (and v) of a one-dof joint."""
        return self.model.joints[self.model.getJointId(name)].idx_q

    @staticmethod
    def ik_joint_names(arm: str, use_torso: bool) -> list[str]:
        """The joints IK moves for `arm`: its seven, with the torso lift first when asked."""
        names = robot_model.arm_joint_names(arm)
        return ["torso_lift_joint", *names] if use_torso else list(names)

    def joint_limits(self, names: list[str]) -> list[tuple[float, float]]:
        """(lower, upper) of each named one-dof joint."""
        return [
            (float(self.lower[self.joint_index(n)]), float(self.upper[self.joint_index(n)])) for n in names
        ]

    def inverse(
        self,
        arm: str,
        T_base_target: np.ndarray,
        seed_positions: Mapping[str, float],
        *,
        use_torso: bool = False,
        restarts: int = 30,
        seed: int = 0,
        max_iterations: int = 150,
    ) -> IkResult:
        """Joint positions that put ``gripper_<arm>_grasping_frame`` at ``T_base_target``.

        Damped least squares (damping 1e-3) with joint-limit clamping; the first attempt starts
        from ``seed_positions`` (so the nearest solution wins), then seeded random restarts.
        """
        names = self.ik_joint_names(arm, use_torso)
        indices = np.array([self.joint_index(name) for name in names])
        frame_id = self.model.getFrameId(f"gripper_{arm}_grasping_frame")
        target = pin.SE3(np.asarray(T_base_target, dtype=float))
        rng = np.random.default_rng(seed)
        q_start = self._q(seed_positions)
        best: IkResult | None = None
        for attempt in range(restarts + 1):
            q = q_start.copy()
            if attempt > 0:
                q[indices] = rng.uniform(self.lower[indices], self.upper[indices])
            q, pos_err, rot_err = self._solve(q, indices, frame_id, target, max_iterations)
            result = IkResult(
                pos_err <= IK_POSITION_TOLERANCE and rot_err <= IK_ORIENTATION_TOLERANCE,
                {name: float(q[index]) for name, index in zip(names, indices, strict=True)},
                pos_err,
                rot_err,
                attempt + 1,
            )
            if result.success:
                return result
            if (
                best is None
                or pos_err + 0.1 * rot_err < best.position_error_m + 0.1 * best.orientation_error_rad
            ):
                best = result
        assert best is not None
        log.debug(
            "IK failed for %s: best %.4f m %.4f rad", arm, best.position_error_m, best.orientation_error_rad
        )
        return IkResult(
            False, best.joint_positions, best.position_error_m, best.orientation_error_rad, restarts + 1
        )

    def solutions(
        self,
        arm: str,
        T_base_target: np.ndarray,
        seed_positions: Mapping[str, float],
        *,
        use_torso: bool = False,
        count: int = 4,
        tries: int = 24,
        seed: int = 0,
    ) -> list[dict[str, float]]:
        """Up to `count` different joint solutions for ``T_base_target`` (no two within
        DISTINCT_SOLUTION_RAD on every joint), least joint travel from ``seed_positions`` first: the
        seeded solve, then solves from `tries` random starts. Why: one joint-space move to the nearest
        solution may sweep through something another solution passes clear of."""
        names = self.ik_joint_names(arm, use_torso)
        limits = self.joint_limits(names)
        rng = np.random.default_rng(seed)
        found: list[dict[str, float]] = []
        for attempt in range(tries + 1):
            start = dict(seed_positions)
            if attempt:
                start.update(
                    {n: float(rng.uniform(low, high)) for n, (low, high) in zip(names, limits, strict=True)}
                )
            result = self.inverse(arm, T_base_target, start, use_torso=use_torso, restarts=0)
            if result.success and all(
                max(abs(result.joint_positions[n] - other[n]) for n in names) > DISTINCT_SOLUTION_RAD
                for other in found
            ):
                found.append(result.joint_positions)
                if len(found) >= count:
                    break

        def travel(joints: dict[str, float]) -> float:
            return max(abs(value - seed_positions.get(name, value)) for name, value in joints.items())

        return sorted(found, key=travel)

    def _solve(
        self, q: np.ndarray, indices: np.ndarray, frame_id: int, target: pin.SE3, max_iterations: int
    ) -> tuple[np.ndarray, float, float]:
        # Small arrays: numpy's per-call overhead, not arithmetic, sets the pace here, so the loop
        # avoids np.linalg.norm and np.clip and indexes the joint limits once.
        eye = np.eye(6)
        lower, upper = self.lower[indices], self.upper[indices]
        pos_err = rot_err = float("inf")
        best_err, best_at = float("inf"), 0
        for iteration in range(max_iterations):
            pin.forwardKinematics(self.model, self.data, q)
            pin.updateFramePlacement(self.model, self.data, frame_id)
            current = self.data.oMf[frame_id]
            error = pin.log6(current.actInv(target)).vector
            offset = target.translation - current.translation
            pos_err = math.sqrt(offset @ offset)
            rot_err = math.sqrt(error[3:] @ error[3:])
            if pos_err <= IK_POSITION_TOLERANCE * 0.2 and rot_err <= IK_ORIENTATION_TOLERANCE * 0.2:
                break
            # Stalled (pinned at joint limits, or a local minimum): further iterations change nothing,
            # so give the time to the next restart instead.
            if pos_err + 0.1 * rot_err < best_err - IK_STALL_PROGRESS:
                best_err, best_at = pos_err + 0.1 * rot_err, iteration
            elif iteration - best_at >= IK_STALL_ITERATIONS:
                break
            jacobian = pin.computeFrameJacobian(self.model, self.data, q, frame_id, pin.LOCAL)[:, indices]
            step = jacobian.T @ np.linalg.solve(jacobian @ jacobian.T + IK_DAMPING * eye, error)
            q[indices] = np.minimum(np.maximum(q[indices] + step, lower), upper)
        return q, pos_err, rot_err


@lru_cache(maxsize=1)
def default_kinematics() -> RobotKinematics:
    """A shared instance for single-threaded callers."""
    return RobotKinematics()


def forward(joint_positions: Mapping[str, float], frame: str) -> np.ndarray:
    """T_base_frame of ``frame`` for the given joint positions (URDF joint names)."""
    return default_kinematics().forward(joint_positions, frame)


def top_down_grasp(position: np.ndarray, yaw: float) -> np.ndarray:
    """T_base_grasp for a vertical approach from above: x down, closing axis y at heading ``yaw + 90 deg``.

    ``yaw`` is the heading of the plate's long side, so the fingers close across the short side.
    """
    c, s = np.cos(yaw), np.sin(yaw)
    x_axis = np.array([0.0, 0.0, -1.0])
    y_axis = np.array([-s, c, 0.0])
    z_axis = np.cross(x_axis, y_axis)
    transform = np.eye(4)
    transform[:3, :3] = np.column_stack([x_axis, y_axis, z_axis])
    transform[:3, 3] = position
    return transform


HEAD_LIMIT_MARGIN_RAD = math.radians(1.0)


def within_head_limits(aim: dict[str, float]) -> dict[str, float]:
    """Pan and tilt held HEAD_LIMIT_MARGIN_RAD inside the head's limits: the camera's half field of view
    (18 deg vertically) keeps a target a few degrees beyond them in the image, and a goal beyond a limit
    never arrives (a marker low and near asked for -60.2 deg of tilt: MOTION_FAILED, layout 134099)."""
    limits = {f"{joint.name}_joint": joint.limits_deg for joint in robot_model.HEAD_JOINTS}
    out = dict(aim)
    for name, (low, high) in limits.items():
        if name in out:
            out[name] = min(
                max(out[name], math.radians(low) + HEAD_LIMIT_MARGIN_RAD),
                math.radians(high) - HEAD_LIMIT_MARGIN_RAD,
            )
    return out


def head_angles_towards(kinematics: RobotKinematics, joints: dict[str, float], target: np.ndarray) -> dict:
    """Pan and tilt that point the head at `target` (base_footprint), from the head joint origins."""
    level = {**joints, "head_1_joint": 0.0, "head_2_joint": 0.0}
    pan_origin = kinematics.forward(level, "head_1_link")[:3, 3]
    pan = math.atan2(target[1] - pan_origin[1], target[0] - pan_origin[0])
    tilt_origin = kinematics.forward({**level, "head_1_joint": pan}, "head_2_link")[:3, 3]
    horizontal = math.hypot(target[0] - tilt_origin[0], target[1] - tilt_origin[1])
    tilt = -math.atan2(tilt_origin[2] - target[2], horizontal)  # negative tilt looks down
    for _ in range(3):  # the camera sits off both head axes: centre the target in the image
        optical = kinematics.forward({**level, "head_1_joint": pan, "head_2_joint": tilt}, CAMERA_FRAME)
        x, y, z = tf.invert(optical)[:3, :3] @ (target - optical[:3, 3])  # z ahead, x right, y down
        pan -= math.atan2(x, z)
        tilt -= math.atan2(y, z)
    return {"head_1_joint": pan, "head_2_joint": tilt}


def head_aim(kinematics: RobotKinematics, joints: dict[str, float], target: np.ndarray) -> dict[str, float]:
    """Pan and tilt, within the head's limits, that centre `target` (base_footprint) in the image."""
    return within_head_limits(head_angles_towards(kinematics, joints, target))
