"""What the base, arm and gripper goals do: navigate, dock, undock, play motion, gripper.

Each method is an execute function for action_servers.RobotActionServers: it validates the goal
(raising ActionAbort with a code and a reason before anything moves), then reads and commands the
hardware (robot_port) through the goal's GoalRun. Parameters (POIs, speeds) are read from the node's
current ROS parameters at goal time, so changing them at runtime takes effect on the next goal.
Lives on: rclpy executor threads (one goal at a time, see MotionSlot).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
from labware_interfaces.msg import ErrorCodes

from lab_description.serviceability import WORKING_CLEARANCE
from robot_port.types import ARM_SIDES, JointTrajectory
from tiago_description import robot_model as rm
from tiago_description.motion_library import HOTEL_MOTIONS, MotionLibrary
from tiago_description.transforms import from_planar, invert
from tiago_skills.arm_planning import ArmPlanning
from tiago_skills.drive_estimate import planned_drive_s
from tiago_skills.drive_posture import posture_for_drive
from tiago_skills.goal_run import ActionAbort, GoalRun
from tiago_skills.grasp_check import grasp_width_problem
from tiago_skills.grasp_twins import twin_pose, twin_times, twin_with_a_way_down
from tiago_skills.joint_commands import keyframe_points, move_joints
from tiago_skills.tool_path import tool_trajectory

log = logging.getLogger(__name__)

# Straight tool moves (m/s along the line; joint limits cap them too): slow where the plate enters a
# nest or hotel pocket, where chamfers guide it; faster in free space (approach, lift, carry).
TOOL_SPEED_INTO_POCKET = 0.08
# 0.15 once "lost the plate" (SLOT_EMPTY): that was the hotel tray hitting the table, see base_alignment
TOOL_SPEED_FREE = 0.35
CREEP_HEIGHT = 0.018  # m above a pocket where the slow creep starts (rims: nest 6 mm, hotel 8 mm)

# The tool stays this far ahead of the base (m) while it is in front of every bench: a bench's front
# edge stands at least WORKING_CLEARANCE ahead of a working pose (the loader's rule), and an open
# finger reaches OPEN_FINGER_REACH past the grasping frame along the closing axis, which points at
# the bench at a nest. Moves between a bench and the hotel or a fixed posture pass this line level,
# so on a standing bench (0.90 m) nothing dips onto its edge (seen: a finger 0.8 mm into the edge in
# "Benchtop"; a straight line from a nest's approach to the hotel passed 2 mm over it).
OPEN_FINGER_REACH = rm.FINGER_MOUNT_OFFSET + rm.FINGER_TRAVEL + rm.PAD_THICKNESS
BENCH_EDGE_MARGIN = 0.02
BENCH_FRONT_X = WORKING_CLEARANCE - OPEN_FINGER_REACH - BENCH_EDGE_MARGIN


class RobotBehaviours:
    """Execute functions of the robot-level actions (one instance per robot)."""

    def __init__(
        self,
        *,
        poi_pose: Callable[[str], tuple[float, float, float] | None],
        poi_names: Callable[[], list[str]],
        dock_poi: Callable[[], str],
        hotel_slots: int,
        motions: MotionLibrary,
        speed_scale: Callable[[], float],
        seed: int | None = None,
        plate_widths: tuple[float, ...] = (),
        station_pois: frozenset[str] = frozenset(),
        marker_at_poi: Callable[[str], np.ndarray | None] = lambda _poi: None,
    ) -> None:
        self.poi_pose = poi_pose
        self.poi_names = poi_names
        self.dock_poi = dock_poi
        self.hotel_slots = hotel_slots
        self.motions = motions
        self.speed_scale = speed_scale
        self.plate_widths = plate_widths  # the short sides of the lab's plate types: what a grasp spans
        self.station_pois = station_pois  # a drive to one of these ends with the torso at the bench height
        self.marker_at_poi = marker_at_poi  # T_world_marker of the station a POI serves: the head aims there
        self.planning = ArmPlanning(seed)
        self.grasp_flipped: dict[str, bool] = {}  # per arm: twin of the top-down grasp last used
        self.twin_wanted: dict[str, bool | None] = {}  # per arm: the one twin the next put's nest reaches
        self.holding: dict[str, bool] = {}  # per arm: the last gripper command closed on a plate
        self.bench_exit: Callable[[GoalRun, str, np.ndarray, tuple[float, float]], bool] | None = None

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
    def known_poi(self, name: str) -> tuple[float, float, float]:
        pose = self.poi_pose(name)
        if pose is None:
            raise ActionAbort(
                ErrorCodes.UNKNOWN_POI, f"unknown POI {name!r}: known are {', '.join(self.poi_names())}"
            )
        return pose

    def navigate(self, run: GoalRun, goal: Any) -> dict:
        pose = self.known_poi(goal.poi)
        if run.read(lambda hardware: hardware.is_docked()):
            raise ActionAbort(ErrorCodes.DOCKED, "the robot is docked: undock first")
        to_station = goal.poi in self.station_pois
        marker = self.marker_at_poi(goal.poi)
        head = None if marker is None else partial(self.head_towards, pose, marker)
        torso = posture_for_drive(run, self.motions, self.speed_scale(), to_station, head)
        try:
            # The drive has the whole progress: the torso moves beside it and nearly always stands
            # before the base arrives. With a share kept for the torso, the drive's last report said
            # 95 % done and 0 s left while nothing was left to do (a client saw it under load:
            # test_remaining_time_is_never_zero_while_the_robot_still_moves[prepare] in CI); a torso
            # still moving after the drive reports its own remaining time at 100 %.
            name = f"POI {goal.poi!r}"
            run.follow(
                lambda hardware: hardware.navigate_to(pose, name),
                span=(0.0, 1.0),
                while_running=None if torso is None else torso.poll,
            )
            if torso is not None:
                torso.finish()
        except BaseException:
            run.stop([] if torso is None else list(torso.executions))  # a cancelled drive stops them
            raise
        return {}

    def head_towards(
        self, poi: tuple[float, float, float], T_world_marker: np.ndarray, torso_m: float
    ) -> dict[str, float]:
        """Head angles that look at a station's marker from its POI with the torso at `torso_m`."""
        T_base_marker = invert(from_planar(*poi)) @ T_world_marker
        return self.planning.head_towards({"torso_lift_joint": torso_m}, T_base_marker[:3, 3])

    def dock(self, run: GoalRun, _goal: Any) -> dict:
        if run.read(lambda hardware: hardware.is_docked()):
            return {}
        pose = self.poi_pose(self.dock_poi())
        if pose is not None:
            name = f"the dock POI {self.dock_poi()!r}"
            run.follow(lambda hardware: hardware.navigate_to(pose, name), span=(0.0, 0.6), later_s=10.0)
        run.follow(lambda hardware: hardware.dock(), span=(0.6 if pose is not None else 0.0, 1.0))
        return {}

    def undock(self, run: GoalRun, goal: Any) -> dict:
        goal_pose = self.known_poi(goal.then_poi) if goal.then_poi else None  # refused before it moves
        if not run.read(lambda hardware: hardware.is_docked()):
            return {}
        dock = self.poi_pose(self.dock_poi())  # where the undock ends
        later_s = 0.0 if goal_pose is None else planned_drive_s(run, dock, goal_pose)
        run.follow(lambda hardware: hardware.undock(), later_s=later_s)
        return {}

    # -- arm ----------------------------------------------------------------------------
    def play_motion(self, run: GoalRun, goal: Any) -> dict:
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
        frames = self.motions.frames_for(name, arm)
        # Every fixed motion leaves the hotel straight up to the carry height first: a held plate is
        # never swept through the hotel, and an empty gripper folding from the hotel's approach pose
        # (0.71 m high) swings its pads up to 0.40 m ahead of the base at 0.77 m, where a bench's front
        # edge (0.36 .. 0.45 m ahead at a working pose, top up to 0.78 m) stands: Tuck after
        # GetLabware has grazed such an edge 1.5 mm deep. From the carry height the fold
        # stays above 0.85 m (tests/tiago_description/test_fold_sweep.py).
        first = self.leave_hotel(run, arm) or self.leave_bench(run, arm)
        speed = self.speed_scale() * self.motions.speed_scale
        # All keyframes as one trajectory, as PAL's play_motion2 sends them: the joints pass each
        # keyframe without stopping (a stop at each cost a ramp down and up, about 0.3 s a keyframe).
        joints = run.read(lambda hardware: dict(hardware.joint_positions()))
        trajectory = JointTrajectory(keyframe_points(joints, frames), speed)
        run.follow(lambda hardware: hardware.follow_joint_trajectory(trajectory), span=(first, 1.0))
        return {}

    def grasp_twin(
        self, arm: str, T_base_grasp: np.ndarray, seed: dict[str, float], *, only: bool | None = None
    ) -> np.ndarray:
        """A top-down grasp pose or its twin with the fingers swapped (half-turn about the approach).

        With a plate in the gripper, the twin used when it was grasped, so the plate keeps its
        orientation from nest to hotel and back; otherwise `only` if given, else the one a put's nest
        needs (`twin_wanted`: the twin that fetches a plate from the hotel is the one that puts it
        down) if it reaches, else the one the arm reaches sooner (`move_s`: 0.2 m of torso takes
        2.9 s, 2.8 rad of an arm joint about 1.5 s).
        """
        if self.holding.get(arm):
            order = [self.grasp_flipped.get(arm, False)]
        else:
            order = [False, True] if only is None else [only]
        duration = twin_times(self.planning, arm, T_base_grasp, seed, order)
        if duration:
            wanted = None if self.holding.get(arm) else self.twin_wanted.get(arm)
            flip = wanted if wanted in duration else min(duration, key=duration.get)
            self.grasp_flipped[arm] = flip
            return twin_pose(T_base_grasp, flip)
        raise ActionAbort(
            ErrorCodes.IK_FAILED, f"the {arm} arm cannot reach {np.round(T_base_grasp[:3, 3], 3)}"
        )

    def hotel_grasp_pose(self, slot: int, approach: bool, releasing: bool = False) -> np.ndarray:
        T_base_slot = self.planning.frame_pose({}, f"hotel_slot_{slot}")
        return T_base_slot @ self.motions.hotel.T_slot_grasp(approach, releasing)

    def _tool_move(
        self,
        run: GoalRun,
        arm: str,
        T_base_grasp: np.ndarray,
        span: tuple[float, float],
        *,
        free: bool = False,
        tool_speed: float = TOOL_SPEED_FREE,
        only: bool | None = None,
    ) -> None:
        """Straight tool move to a top-down grasp pose; with `free`, a joint-space move when the
        gripper is empty or no straight line exists (e.g. from the folded arm, where nothing is in
        the way)."""
        seed = run.read(lambda hardware: dict(hardware.joint_positions()))
        target = self.grasp_twin(arm, T_base_grasp, seed, only=only)
        if free and not self.holding.get(arm):  # an empty gripper from the tucked arm: the short way
            self.joint_space_move(run, arm, target, span)
            return
        try:
            self.straight_move(run, arm, target, tool_speed, span)
        except ActionAbort as abort:
            if not free or abort.code != ErrorCodes.IK_FAILED:
                raise
            self.joint_space_move(run, arm, target, span)

    def into_pocket(
        self, run: GoalRun, arm: str, T_base_grasp: np.ndarray, span: tuple[float, float]
    ) -> None:
        """Down into a nest or hotel pocket: fast to CREEP_HEIGHT above it, then slowly the rest."""
        joints = run.read(lambda hardware: dict(hardware.joint_positions()))
        height = self.planning.tool_pose(arm, joints)[2, 3] - T_base_grasp[2, 3]
        low, high = span
        if height > CREEP_HEIGHT + 0.01:
            T_above = T_base_grasp.copy()
            T_above[2, 3] += CREEP_HEIGHT
            middle = low + (high - low) * 0.6
            self.straight_move(run, arm, T_above, TOOL_SPEED_FREE, (low, middle))
            low = middle
        self.straight_move(run, arm, T_base_grasp, TOOL_SPEED_INTO_POCKET, (low, high))

    def straight_move(
        self, run: GoalRun, arm: str, T_base_grasp: np.ndarray, tool_speed: float, span: tuple[float, float]
    ) -> None:
        """Straight tool move by the arm alone if it can (the torso lifts at only 0.07 m/s and would
        set the pace of every vertical move), else with the torso. A path that fails its IK check
        fails before anything moves, so the second try starts from the same state."""
        try:
            line = self.tool_line(run, arm, T_base_grasp, tool_speed, use_torso=False)
        except ActionAbort as abort:
            if abort.code != ErrorCodes.IK_FAILED:
                raise
            log.info("the arm alone cannot follow the line (%s): planning with the torso", abort.message)
            line = self.tool_line(run, arm, T_base_grasp, tool_speed, use_torso=True)
        run.follow(lambda hardware: hardware.follow_joint_trajectory(line), span=span)

    def tool_line(
        self, run: GoalRun, arm: str, T_base_grasp: np.ndarray, tool_speed: float, *, use_torso: bool
    ) -> JointTrajectory:
        """The joint trajectory that moves the grasping frame along a straight line to T_base_grasp
        at up to `tool_speed` (m/s; the joints' limits cap it too); IK_FAILED naming the waypoint
        where no line exists."""
        current = run.read(lambda hardware: dict(hardware.joint_positions()))
        planned = self.planning.plan_line(arm, current, T_base_grasp, use_torso=use_torso)
        if isinstance(planned, str):
            raise ActionAbort(ErrorCodes.IK_FAILED, planned)
        return tool_trajectory(planned, tool_speed)

    def joint_space_move(
        self, run: GoalRun, arm: str, T_base_grasp: np.ndarray, span: tuple[float, float]
    ) -> None:
        """Where no straight tool path exists (e.g. from the folded arm): one joint-space move.

        The arm alone first (the torso lifts at only 0.07 m/s and would set the pace), the torso too
        only if the arm alone cannot reach; 60 seeded IK restarts rather than the simulator's 30
        (30 have found no solution for the hotel from the tucked arm).
        """
        log.info("no straight path to %s: moving in joint space", np.round(T_base_grasp[:3, 3], 3))
        seed = run.read(lambda hardware: dict(hardware.joint_positions()))
        joints = self.planning.plan_joint_move(arm, seed, T_base_grasp)
        if joints is None:
            raise ActionAbort(
                ErrorCodes.IK_FAILED, f"the {arm} arm cannot reach {np.round(T_base_grasp[:3, 3], 3)}"
            )
        speed = self.speed_scale() * self.motions.speed_scale
        run.follow(move_joints(joints, speed), span=span)

    def _over_slot(self, arm: str, joints: dict[str, float], slot: int, radius_m: float) -> bool:
        tool = self.planning.tool_pose(arm, joints)[:3, 3]
        return float(np.hypot(*(tool[:2] - self.hotel_grasp_pose(slot, True)[:2, 3]))) < radius_m

    def leave_hotel(self, run: GoalRun, arm: str) -> float:
        """If the tool is over a hotel slot, rise straight to the carry height; returns progress used."""
        joints = run.read(lambda hardware: dict(hardware.joint_positions()))
        for slot in range(1, self.hotel_slots + 1):
            if self._over_slot(arm, joints, slot, 0.05):
                T_carry = self.planning.tool_pose(arm, joints)
                T_carry[2, 3] = self.hotel_grasp_pose(slot, True)[2, 3] + self.motions.hotel.carry_height_m
                self.straight_move(run, arm, T_carry, TOOL_SPEED_FREE, (0.0, 0.3))
                return 0.3
        return 0.0

    def leave_bench(self, run: GoalRun, arm: str) -> float:
        """If the tool is over a bench (ahead of BENCH_FRONT_X), go back to that line at its height
        first, straight if it can, else by the first way clear of the station's board, bench and
        labware (`bench_exit`); returns the progress used."""
        joints = run.read(lambda hardware: dict(hardware.joint_positions()))
        T_tool = self.planning.tool_pose(arm, joints)
        if T_tool[0, 3] <= BENCH_FRONT_X + BENCH_EDGE_MARGIN / 2:  # on the line ("Benchtop"), or behind it
            return 0.0
        T_front = T_tool.copy()
        T_front[0, 3] = BENCH_FRONT_X
        try:
            self.straight_move(run, arm, T_front, TOOL_SPEED_FREE, (0.0, 0.3))
        except ActionAbort as abort:
            if abort.code != ErrorCodes.IK_FAILED:
                raise
            # Near the body the wrist may have to turn over along the line (a joint jump)
            log.info("no straight way back from over the bench (%s)", abort.message)
            if self.bench_exit is None or not self.bench_exit(run, arm, T_front, (0.0, 0.3)):
                self.joint_space_move(run, arm, T_front, (0.0, 0.3))  # no station seen: one unchecked move
        return 0.3

    def rise_before_bench(self, run: GoalRun, arm: str, T_base_target: np.ndarray, first: float) -> float:
        """Before the tool goes over a bench to a target higher than itself, rise straight up to the
        target's height where it is (in front of the bench); returns the progress used so far."""
        joints = run.read(lambda hardware: dict(hardware.joint_positions()))
        T_tool = self.planning.tool_pose(arm, joints)
        if T_base_target[0, 3] <= BENCH_FRONT_X or T_tool[0, 3] > BENCH_FRONT_X + BENCH_EDGE_MARGIN:
            return first
        if T_tool[2, 3] >= T_base_target[2, 3] - 0.005:
            return first
        T_up = T_tool.copy()
        T_up[2, 3] = T_base_target[2, 3]
        middle = first + (1.0 - first) * 0.4
        self.straight_move(run, arm, T_up, TOOL_SPEED_FREE, (first, middle))
        return middle

    def _hotel_motion(self, run: GoalRun, arm: str, name: str, slot: int) -> None:
        T_approach = self.hotel_grasp_pose(slot, approach=True)
        if name == "Nest":  # straight down into the pocket (back up: NestApproach)
            T_nest = self.hotel_grasp_pose(slot, approach=False, releasing=self.holding.get(arm, False))
            seed = run.read(lambda hardware: dict(hardware.joint_positions()))
            self.into_pocket(run, arm, self.grasp_twin(arm, T_nest, seed), (0.0, 1.0))
            return
        joints = run.read(lambda hardware: dict(hardware.joint_positions()))
        if self._over_slot(arm, joints, slot, 0.03):  # straight up or down to the approach pose
            self._tool_move(run, arm, T_approach, (0.0, 1.0))
            return
        # From elsewhere: off the bench, straight to the carry height above the slot, then straight down.
        first = self.leave_bench(run, arm)
        T_carry = T_approach.copy()
        T_carry[2, 3] += self.motions.hotel.carry_height_m
        twin = None
        if not self.holding.get(arm):
            seed = run.read(lambda hardware: dict(hardware.joint_positions()))
            twin = twin_with_a_way_down(
                self.planning, arm, seed, (T_carry, T_approach), self.twin_wanted.get(arm)
            )
        self._tool_move(run, arm, T_carry, (first, 0.7), free=True, only=twin)
        self._tool_move(run, arm, T_approach, (0.7, 1.0), only=twin)

    # -- gripper ------------------------------------------------------------------------
    def gripper(self, run: GoalRun, goal: Any) -> dict:
        arm = self.arm_of(goal.arm)
        if goal.command not in ("open", "close"):
            raise ActionAbort(
                ErrorCodes.BAD_GOAL, f"unknown gripper command {goal.command!r}: use open or close"
            )
        close = goal.command == "close"
        self.holding[arm] = False if not close else self.holding.get(arm, False)
        execution = run.follow(lambda hardware: hardware.gripper(arm, close))
        holding = bool(execution.result.get("holding", False))
        self.holding[arm] = close and holding
        opening = float(execution.result.get("opening_m", math.nan))
        problem = grasp_width_problem(opening, self.plate_widths) if close and holding else ""
        if problem:
            raise ActionAbort(ErrorCodes.GRASP_FAILED, problem)
        return {"holding": holding, "opening_m": opening}
