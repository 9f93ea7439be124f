"""The arm's way from in front of a bench to above a nest, clear of the station's marker board, its
bench and the labware in its nests.

Why: the marker stands on a board beside the row (furniture as a lab has it: 2 to 8 cm beyond the end
nest's brackets), and the arm's usual ways to the end nest beside it, a straight tool line or one
joint-space move, swept a finger, the wrist or a held plate into the board (random layouts 132035,
132040, 132016); a joint-space move also dipped a finger into the bench top, and one swept a finger
through the plate in the target nest (181006). The ways are planned first and checked against the
board, the bench and the labware that may stand in the nests, placed where the marker is seen, with
the robot model's collision shapes (`tiago_description.arm_clearance`); the first that keeps WAY_CLEARANCE_M
runs, tried in this order, each to the grasp and then to its twin with the fingers swapped (an empty
gripper only: a held plate keeps its orientation):

1. the straight tool line (the arm alone, else with the torso);
2. a joint-space move, to each of several IK solutions;
3. via a pose in front of the bench, then straight in: in line with the nest on the bench's front line
   (`BENCH_FRONT_X`), or where the tool is, turned as at the target. The way there is a straight line
   or a joint-space move, the line in planned backwards from the target's IK solutions;
4. around: a joint-space way searched around the boxes and the robot's own body (`joint_rrt`).

None clear: IK_FAILED naming each way's nearest pass, before anything moves. From in or just above
the nest the tool only moves straight (marker_motion), and no way is chosen. Lives on the goal's thread.
"""

from __future__ import annotations

import itertools
import logging
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from labware_interfaces.msg import ErrorCodes

from lab_description.world import Station
from labware_model.labware import LabwareType
from robot_port.types import JointTrajectory
from tiago_description import transforms as tf
from tiago_description.arm_clearance import Box, HeldBox, joint_path
from tiago_description.motion_library import HotelGrasp
from tiago_skills.behaviours import BENCH_FRONT_X, RobotBehaviours
from tiago_skills.goal_run import ActionAbort, GoalRun
from tiago_skills.perception.site_frames import upright_marker
from tiago_skills.tool_path import tool_trajectory

log = logging.getLogger(__name__)

WAY_CLEARANCE_M = 0.012
"""The least distance a planned way keeps between the arm, its gripper or a held plate and the
marker's board or the bench (m): their poses come from the marker seen (a few mm), the arm follows
its trajectory to a few mm, and the contacts seen were 0.5 to 2.3 mm deep."""
FRONT_DETOUR_MIN_M = 0.05
"""The way via the nest's front is tried only for a target at least this far beyond the front line."""


@dataclass(frozen=True)
class Way:
    """A planned way: the trajectories to run in order and every configuration they pass."""

    name: str
    trajectories: tuple[JointTrajectory, ...]
    path: tuple[dict[str, float], ...]

    @property
    def end(self) -> dict[str, float]:
        return self.path[-1]

    def then(self, other: Way) -> Way:
        return Way(self.name, self.trajectories + other.trajectories, self.path + other.path)

    def reversed(self, start: dict[str, float], tool_speed: float) -> Way:
        """The same straight line run the other way, to `start` (where this way began)."""
        back = (*reversed(self.path[:-1]), start)
        joints = self.trajectories[-1].joint_names
        points = [{name: point[name] for name in joints} for point in back]
        return Way(self.name, (tool_trajectory(points, tool_speed),), back)


def board_box(station: Station, T_base_marker_seen: np.ndarray) -> Box:
    """The station's marker board in base_footprint, placed where the marker is seen (levelled on the
    bench like the nests, `upright_marker`)."""
    T_base_marker = upright_marker(T_base_marker_seen, station.T_table_marker())
    return Box(
        f"{station.name} marker board", station.marker_board_size(), T_base_marker @ station.T_marker_board()
    )


def bench_box(station: Station, T_base_marker_seen: np.ndarray) -> Box:
    """The station's bench in base_footprint, placed where the marker is seen: a joint-space move
    dipped a finger 1.6 mm into the bench top on its way to a nest (test_bench_route)."""
    T_base_marker = upright_marker(T_base_marker_seen, station.T_table_marker())
    depth, width, height = station.table_size
    T_base_middle = (
        T_base_marker @ tf.invert(station.T_table_marker()) @ tf.make_transform((0.0, 0.0, -height / 2))
    )
    return Box(f"{station.name} bench", (depth, width, height), T_base_middle)


def station_boxes(station: Station, T_base_marker_seen: np.ndarray) -> list[Box]:
    """What a way to a nest must keep clear of: the station's marker board and its bench."""
    return [board_box(station, T_base_marker_seen), bench_box(station, T_base_marker_seen)]


def largest_labware(labware_types: list[LabwareType]) -> tuple[float, float, float]:
    """Length, width and height (m) that every labware type of the lab fits in."""
    return (
        max(t.length for t in labware_types),
        max(t.width for t in labware_types),
        max(t.height for t in labware_types),
    )


def nest_labware_boxes(
    station: Station,
    T_base_marker_seen: np.ndarray,
    sub_positions: list[int],
    size: tuple[float, float, float],
) -> list[Box]:
    """Labware standing in these nests (as large as `size`: length, width, height), placed where the
    marker is seen: a joint-space move to the approach above a nest swept a finger through the plate
    it came for and pushed it out of its nest (random layout 181006), and the descent to grasp it
    stopped short."""
    T_base_marker = upright_marker(T_base_marker_seen, station.T_table_marker())
    height = size[2]
    return [
        Box(
            f"the labware in {station.name} nest {sub_position}",
            size,
            T_base_marker @ station.T_marker_site(sub_position) @ tf.make_transform((0.0, 0.0, height / 2)),
        )
        for sub_position in sub_positions
    ]


def held_plate_box(labware_types: list[LabwareType], grasp: HotelGrasp) -> HeldBox:
    """The largest plate the lab has, as the gripper holds it: the grasping frame's x points down
    into the plate (its bottom `grasp_height_m` below the frame), y across its short side, z along its
    long side."""
    length, width, height = largest_labware(labware_types)
    return HeldBox((height, width, length), tf.make_transform((grasp.grasp_height_m - height / 2, 0.0, 0.0)))


class BenchRoute:
    """Chooses and runs the first clear way to a target above a bench (one instance per robot)."""

    def __init__(self, behaviours: RobotBehaviours) -> None:
        self.behaviours = behaviours

    def move(
        self,
        run: GoalRun,
        arm: str,
        targets: list[np.ndarray],
        tool_speed: float,
        span: tuple[float, float],
        boxes: list[Box],
        held: HeldBox | None,
    ) -> int:
        """Move the grasping frame to one of `targets` (the same grasp's twins, preferred first) by the
        first clear way (`plan`); returns the index of the target reached."""
        start = run.read(lambda hardware: dict(hardware.joint_positions()))
        index, way = self.plan(arm, start, targets, tool_speed, boxes, held)
        low, high = span
        count = len(way.trajectories)
        for number, trajectory in enumerate(way.trajectories):
            part = (low + (high - low) * number / count, low + (high - low) * (number + 1) / count)
            run.follow(lambda hardware, t=trajectory: hardware.follow_joint_trajectory(t), span=part)
        return index

    def plan(
        self,
        arm: str,
        start: dict[str, float],
        targets: list[np.ndarray],
        tool_speed: float,
        boxes: list[Box],
        held: HeldBox | None,
    ) -> tuple[int, Way]:
        """The first way from `start` (all joint readings) to one of `targets` that keeps
        WAY_CLEARANCE_M from `boxes`, with the target's index; IK_FAILED naming every way tried."""
        tried: list[str] = []
        for index, way in self.ways(arm, start, targets, tool_speed, boxes, held):
            if isinstance(way, str):
                tried.append(way)
                continue
            nearest = self.behaviours.planning.clearance(arm, start, list(way.path), boxes, held)
            if nearest.distance_m < WAY_CLEARANCE_M:
                tried.append(f"{way.name}: {nearest.describe()} at {nearest.index + 1} of {len(way.path)}")
                continue
            if tried:
                where = np.round(targets[index][:3, 3], 3)
                log.info("%s to %s (%s); not: %s", way.name, where, nearest.describe(), "; ".join(tried))
            return index, way
        raise ActionAbort(
            ErrorCodes.IK_FAILED,
            f"no way to {np.round(targets[0][:3, 3], 3)} keeps {WAY_CLEARANCE_M * 1000:.0f} mm from "
            f"the marker board, the bench and the labware in the nests: {'; '.join(tried)}",
        )

    def ways(
        self,
        arm: str,
        start: dict[str, float],
        targets: list[np.ndarray],
        speed: float,
        boxes: list[Box],
        held: HeldBox | None,
    ) -> Iterator[tuple[int, Way | str]]:
        """The ways in the order they are tried, each planned only when the ones before were not clear:
        straight lines, then joint-space moves, then via a pose in front of the bench, each to every
        target in turn."""
        for index, T_target in enumerate(targets):
            yield index, self._line("straight line", arm, start, T_target, speed)
        for index, T_target in enumerate(targets):
            for way in self._joint_moves("joint-space move", arm, start, T_target):
                yield index, way
        T_tool = self.behaviours.planning.tool_pose(arm, start)
        for index, T_target in enumerate(targets):
            if T_target[0, 3] - BENCH_FRONT_X < FRONT_DETOUR_MIN_M:
                continue
            T_front = T_target.copy()  # in line with the nest, on the bench's front line
            T_front[0, 3] = BENCH_FRONT_X
            T_turned = T_target.copy()  # where the tool is, turned as at the target
            T_turned[:3, 3] = T_tool[:3, 3]
            for name, T_via in (("via the front", T_front), ("turned first", T_turned)):
                for way in self._via(name, arm, start, T_via, T_target, speed):
                    yield index, way
        for index, T_target in enumerate(targets):
            yield index, self._around(arm, start, T_target, boxes, held)

    def _via(
        self,
        name: str,
        arm: str,
        start: dict[str, float],
        T_via: np.ndarray,
        T_target: np.ndarray,
        speed: float,
    ) -> Iterator[Way | str]:
        """Via a pose in front of the bench, then straight to the target: a straight line to it, or a
        joint-space move to it. The line in is planned backwards
        from each of the target's IK solutions, so it lies in a branch that reaches the target (a line
        planned forwards from a joint-space move's end ran into a joint limit at once)."""
        first = self._line(name, arm, start, T_via, speed)
        if isinstance(first, str):
            yield first
        else:
            second = self._line(name, arm, first.end, T_target, speed)
            yield second if isinstance(second, str) else first.then(second)
        for goal in self.behaviours.planning.joint_move_goals(arm, start, T_target):
            out = self._line(name, arm, {**start, **goal}, T_via, speed)
            if isinstance(out, str):
                yield out
                continue
            inward = out.reversed({**start, **goal}, speed)
            for way in self._joint_moves(name, arm, start, inward.path[0], exact=True):
                yield way if isinstance(way, str) else way.then(inward)

    def _around(
        self, arm: str, start: dict[str, float], T_target: np.ndarray, boxes: list[Box], held: HeldBox | None
    ) -> Way | str:
        """A joint-space way around the boxes and the robot's own body (`joint_rrt`)."""
        name = "around"
        goals = self.behaviours.planning.joint_move_goals(arm, start, T_target)
        points = self.behaviours.planning.way_around(arm, start, goals, boxes, held, WAY_CLEARANCE_M)
        if points is None:
            return f"{name}: none found"
        speed = self.behaviours.speed_scale() * self.behaviours.motions.speed_scale
        path: list[dict[str, float]] = []
        for a, b in itertools.pairwise([start, *points[1:]]):
            path.extend({**start, **configuration} for configuration in joint_path(a, b))
        return Way(name, (JointTrajectory(tuple(points[1:]), speed),), tuple(path))

    def _line(
        self, name: str, arm: str, start: dict[str, float], T_target: np.ndarray, speed: float
    ) -> Way | str:
        why = ""
        for use_torso in (False, True):
            planned = self.behaviours.planning.plan_line(arm, start, T_target, use_torso=use_torso)
            if not isinstance(planned, str):
                path = tuple({**start, **waypoint} for waypoint in planned)
                return Way(name, (tool_trajectory(planned, speed),), path)
            why = planned
        return f"{name}: {why}"

    def _joint_moves(
        self,
        name: str,
        arm: str,
        start: dict[str, float],
        target: np.ndarray | dict[str, float],
        exact: bool = False,
    ) -> Iterator[Way | str]:
        """One joint-space move per IK solution for a target pose (the nearest first: another solution
        may pass clear), or the one move to a configuration (`exact`)."""
        goals = [target] if exact else self.behaviours.planning.joint_move_goals(arm, start, target)
        if not goals:
            yield f"{name}: unreachable"
        speed = self.behaviours.speed_scale() * self.behaviours.motions.speed_scale
        for joints in goals:
            moved = {
                joint: value
                for joint, value in joints.items()
                if joint.startswith(f"arm_{arm}_")
                or (joint == "torso_lift_joint" and abs(value - start[joint]) > 1e-4)
            }
            path = tuple({**start, **configuration} for configuration in joint_path(start, moved))
            yield Way(name, (JointTrajectory((moved,), speed),), path)
