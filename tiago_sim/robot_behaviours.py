"""What the base, arm and gripper goals do: navigate, dock, undock, play motion, gripper.

Each method is an execute function for ros_actions.RobotActionServers: it validates the goal
(raising ActionAbort with a code and a reason before anything moves), then runs Motions on the
sim thread through the goal's ActionRun. Parameters (POIs, speeds) are read from the node's
current ROS parameters at goal time, so changing them at runtime takes effect on the next goal.
Lives on: rclpy executor threads (one goal at a time, see MotionSlot).
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable
from typing import Any

from labware_interfaces.msg import ErrorCodes

from tiago_sim.action_run import ActionAbort, ActionRun
from tiago_sim.kinematics import RobotKinematics
from tiago_sim.motion_library import HOTEL_MOTIONS, MotionLibrary
from tiago_sim.robot_model import ARM_SIDES

log = logging.getLogger(__name__)


class RobotBehaviours:
    """Execute functions of the robot-level actions (one instance per sim node)."""

    def __init__(
        self,
        *,
        poi_pose: Callable[[str], tuple[float, float, float] | None],
        poi_names: Callable[[], list[str]],
        dock_poi: Callable[[], str],
        hotel_slots: int,
        motions: MotionLibrary,
        speed_scale: Callable[[], float],
    ) -> None:
        self.poi_pose = poi_pose
        self.poi_names = poi_names
        self.dock_poi = dock_poi
        self.hotel_slots = hotel_slots
        self.motions = motions
        self.speed_scale = speed_scale
        self.on_keyframe_motion: Callable[[], None] = lambda: None  # e.g. forget marker sightings
        self._kinematics = RobotKinematics()
        self._kinematics_lock = threading.Lock()

    # -- checks ------------------------------------------------------------------------
    def arm_of(self, requested: str) -> str:
        arm = requested or self.motions.default_arm
        if arm not in ARM_SIDES:
            raise ActionAbort(
                ErrorCodes.BAD_GOAL, f"unknown arm {requested!r}: use one of {', '.join(ARM_SIDES)}"
            )
        return arm

    def check_hotel_slot(self, slot: int) -> None:
        if not 1 <= slot <= self.hotel_slots:
            raise ActionAbort(
                ErrorCodes.UNKNOWN_SLOT, f"unknown hotel slot {slot}: the robot has 1..{self.hotel_slots}"
            )

    # -- base ----------------------------------------------------------------------------
    def navigate(self, run: ActionRun, goal: Any) -> dict:
        pose = self.poi_pose(goal.poi)
        if pose is None:
            raise ActionAbort(
                ErrorCodes.UNKNOWN_POI, f"unknown POI {goal.poi!r}: known are {', '.join(self.poi_names())}"
            )
        if run.sim(lambda sim: sim.is_docked()):
            raise ActionAbort(ErrorCodes.DOCKED, "the robot is docked: undock first")
        run.run_motion(lambda sim: sim.drive_to(*pose))
        return {}

    def dock(self, run: ActionRun, _goal: Any) -> dict:
        if run.sim(lambda sim: sim.is_docked()):
            return {}
        pose = self.poi_pose(self.dock_poi())
        if pose is not None:
            run.run_motion(lambda sim: sim.drive_to(*pose), span=(0.0, 0.6), later_s=10.0)
        run.run_motion(lambda sim: sim.dock(), span=(0.6 if pose is not None else 0.0, 1.0))
        return {}

    def undock(self, run: ActionRun, _goal: Any) -> dict:
        if not run.sim(lambda sim: sim.is_docked()):
            return {}
        run.run_motion(lambda sim: sim.undock())
        return {}

    # -- arm ----------------------------------------------------------------------------
    def play_motion(self, run: ActionRun, goal: Any) -> dict:
        arm = self.arm_of(goal.arm)
        name = goal.motion_name
        if name in HOTEL_MOTIONS:
            self.check_hotel_slot(int(goal.hotel_slot))
            self._hotel_motion(run, arm, name, int(goal.hotel_slot))
            return {}
        if name not in self.motions.keyframes:
            raise ActionAbort(
                ErrorCodes.BAD_GOAL, f"unknown motion {name!r}: known are {', '.join(self.motions.names())}"
            )
        self.on_keyframe_motion()
        frames = self.motions.frames_for(name, arm)
        speed = self.speed_scale() * self.motions.speed_scale
        for index, targets in enumerate(frames):
            span = (index / len(frames), (index + 1) / len(frames))
            run.run_motion(lambda sim, targets=targets: sim.move_joints(targets, speed), span=span)
        return {}

    def solve_ik(
        self, arm: str, T_base_grasp: Any, seed_positions: dict[str, float]
    ) -> dict[str, float] | None:
        """Joint targets for the grasping frame at T_base_grasp, or None when unreachable."""
        with self._kinematics_lock:
            result = self._kinematics.inverse(arm, T_base_grasp, seed_positions)
        return dict(result.joint_positions) if result.success else None

    def hotel_grasp_pose(self, slot: int, approach: bool) -> Any:
        with self._kinematics_lock:
            T_base_slot = self._kinematics.forward({}, f"hotel_slot_{slot}")
        return T_base_slot @ self.motions.hotel.T_slot_grasp(approach)

    def _hotel_motion(self, run: ActionRun, arm: str, name: str, slot: int) -> None:
        if name == "NestApproach":
            # Joint-space move (from wherever the arm is) to the pose above the pocket.
            T_base_grasp = self.hotel_grasp_pose(slot, approach=True)
            seed = run.sim(lambda sim: sim.joint_positions())
            targets = self.solve_ik(arm, T_base_grasp, seed)
            if targets is None:
                raise ActionAbort(
                    ErrorCodes.IK_FAILED, f"no arm pose above hotel slot {slot} for the {arm} arm"
                )
            speed = self.speed_scale() * self.motions.speed_scale
            run.run_motion(lambda sim: sim.move_joints(targets, speed))
            return
        # "Nest": straight down into the pocket (and back up by playing NestApproach again).
        T_base_grasp = self.hotel_grasp_pose(slot, approach=False)
        run.run_motion(lambda sim: sim.move_tool(arm, T_base_grasp, True))

    # -- gripper ------------------------------------------------------------------------
    def gripper(self, run: ActionRun, goal: Any) -> dict:
        arm = self.arm_of(goal.arm)
        if goal.command not in ("open", "close"):
            raise ActionAbort(
                ErrorCodes.BAD_GOAL, f"unknown gripper command {goal.command!r}: use open or close"
            )
        close = goal.command == "close"
        motion = run.run_motion(lambda sim: sim.gripper(arm, close))
        opening = float(getattr(motion, "opening_m", math.nan))
        return {"holding": bool(getattr(motion, "holding", False)), "opening_m": opening}
