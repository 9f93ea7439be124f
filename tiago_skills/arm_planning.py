"""The robot model's kinematics as the skills' goals use it: IK, FK, straight tool lines, several IK
solutions for a joint-space move, and how near a planned path passes boxes in the lab.

Why one object behind one lock: goals run on several executor threads, and a pinocchio model's data
is not shared between threads. Pure computation, no hardware.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

from tiago_description.arm_clearance import ArmClearance, Box, Clearance, HeldBox
from tiago_description.kinematics import RobotKinematics, head_aim
from tiago_skills.joint_rrt import plan_around
from tiago_skills.tool_path import plan_tool_path


class ArmPlanning:
    """IK and FK on the robot model, with the seeds of IK restarts drawn from one generator."""

    def __init__(self, seed: int | None = None) -> None:
        self._rng = np.random.default_rng(seed)
        self._kinematics = RobotKinematics()
        self._clearance = ArmClearance(self._kinematics)
        self._lock = threading.Lock()

    def frame_pose(self, joint_positions: dict[str, float], frame: str) -> np.ndarray:
        with self._lock:
            return self._kinematics.forward(joint_positions, frame)

    def solve_ik(
        self, arm: str, T_base_grasp: Any, seed_positions: dict[str, float], *, use_torso: bool = True
    ) -> dict[str, float] | None:
        """Joint targets for the grasping frame at T_base_grasp, or None when unreachable."""
        with self._lock:
            result = self._kinematics.inverse(
                arm, T_base_grasp, seed_positions, use_torso=use_torso, restarts=60
            )
        return dict(result.joint_positions) if result.success else None

    def plan_line(
        self, arm: str, start: dict[str, float], T_base_grasp: np.ndarray, *, use_torso: bool
    ) -> list[dict[str, float]] | str:
        """Joint waypoints moving the grasping frame straight from `start` to T_base_grasp, or why none."""
        with self._lock:
            return plan_tool_path(self._kinematics, self._rng, arm, start, T_base_grasp, True, use_torso)

    def plan_joint_move(
        self, arm: str, start: dict[str, float], T_base_grasp: np.ndarray
    ) -> dict[str, float] | None:
        """Joint targets for one joint-space move to T_base_grasp: the arm alone if it reaches (the torso
        lifts at only 0.07 m/s and would set the pace), else with the torso; None if neither does."""
        return self.solve_ik(arm, T_base_grasp, start, use_torso=False) or self.solve_ik(
            arm, T_base_grasp, start
        )

    def joint_move_goals(
        self, arm: str, start: dict[str, float], T_base_grasp: np.ndarray
    ) -> list[dict[str, float]]:
        """Several joint targets for a joint-space move to T_base_grasp, least travel first: the arm
        alone if it reaches, else with the torso (`RobotKinematics.solutions`); at the edge of reach,
        where those few starts find none, the one `solve_ik` finds (the solve that judged the target
        reachable: without it a route to an approach 0.97 m high found no way, IK_FAILED)."""
        for use_torso in (False, True):
            with self._lock:
                found = self._kinematics.solutions(
                    arm, T_base_grasp, start, use_torso=use_torso, seed=int(self._rng.integers(1 << 30))
                )
            if found:
                return found
        thorough = self.solve_ik(arm, T_base_grasp, start)
        return [thorough] if thorough is not None else []

    def clearance(
        self,
        arm: str,
        start: dict[str, float],
        path: list[dict[str, float]],
        boxes: list[Box],
        held: HeldBox | None,
    ) -> Clearance:
        """The arm's and a held plate's nearest pass to `boxes` along `path` (`arm_clearance`)."""
        with self._lock:
            return self._clearance.nearest(arm, start, path, boxes, held)

    def head_towards(self, joint_positions: dict[str, float], target: np.ndarray) -> dict[str, float]:
        """Head angles (within their limits) that centre `target` (base_footprint) in the image."""
        with self._lock:
            return head_aim(self._kinematics, joint_positions, target)

    def tool_pose(self, arm: str, joint_positions: dict[str, float]) -> np.ndarray:
        return self.frame_pose(joint_positions, f"gripper_{arm}_grasping_frame")

    def way_around(
        self,
        arm: str,
        start: dict[str, float],
        goals: list[dict[str, float]],
        boxes: list[Box],
        held: HeldBox | None,
        clearance_m: float,
    ) -> list[dict[str, float]] | None:
        """Joint waypoints from `start` to one of `goals` (IK solutions, the same joints each) that keep
        `clearance_m` from `boxes` and from the rest of the robot (`joint_rrt`), or None. Where the start
        itself is nearer than that (it stands where an earlier motion left it), the way keeps what the
        start keeps, less 2 mm."""
        if not goals:
            return None
        names = list(goals[0])
        with self._lock:
            scene = self._clearance.scene(arm, boxes, held, body=True)
            kinematics = self._kinematics
            limits = np.array(kinematics.joint_limits(names))
            least = min(clearance_m, scene.nearest(kinematics.configuration(start)).distance_m - 0.002)

            def is_free(x: np.ndarray) -> bool:
                q = kinematics.configuration({**start, **dict(zip(names, x.tolist(), strict=True))})
                return scene.nearest(q).distance_m >= least

            path = plan_around(
                is_free,
                np.array([start[n] for n in names]),
                [np.array([goal[n] for n in names]) for goal in goals],
                limits[:, 0],
                limits[:, 1],
                self._rng,
            )
        return None if path is None else [dict(zip(names, x.tolist(), strict=True)) for x in path]
