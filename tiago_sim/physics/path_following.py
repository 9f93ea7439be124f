"""Following a planned path: one closed-loop drive per straight segment, within TIAGo's limits.

Why rest-to-rest segments: the planner's corners are exactly the places where the hotel tray's
turning sweep is free, so the robot turns in place there and nowhere else; between corners it
drives straight (DriveMotion: trapezoidal speed within the speed and acceleration limits, heading
loop on the pose estimate). Each segment ends facing the next one, the last at the goal heading,
so the path ends at the goal pose exactly as a single drive did. A segment marked reverse is
driven backwards (leaving or entering a bench's inflated zone along the heading). Progress is the
share of the path length done; the remaining time is the running segment's estimate plus the
estimates of the segments after it. Lives on the sim thread.
"""

from __future__ import annotations

import math

from tiago_description.drive_timing import segment_durations_s
from tiago_description.robot_limits import active_limits
from tiago_sim.navigation.planner import Plan
from tiago_sim.physics.base_controller import DiffDriveBase, DriveMotion, wrap_angle
from tiago_sim.physics.motion import SequenceMotion

TURN_WEIGHT_M = 0.1
"""Progress weight of a segment beyond its length (m): a turn in place is progress too."""


def _bearing(a: tuple[float, float], b: tuple[float, float], reverse: bool) -> float:
    """The heading the robot has while driving from a to b (backwards when `reverse`)."""
    heading = math.atan2(b[1] - a[1], b[0] - a[0])
    return wrap_angle(heading + math.pi) if reverse else heading


def plan_poses(plan: Plan, goal_yaw: float) -> tuple[tuple[float, float, float], ...]:
    """The plan as the navigation stack hands it out (the hardware port's `plan_path`): each waypoint
    with the heading the base drives on from it (backwards on a reverse segment), the goal last."""
    points, segments = plan.waypoints, len(plan.waypoints) - 1
    poses = [
        (*points[i], _bearing(points[i], points[i + 1], _reversed(plan, i, segments)))
        for i in range(segments)
    ]
    return (*poses, (*points[-1], goal_yaw))


def _reversed(plan: Plan, index: int, segments: int) -> bool:
    return (index == 0 and plan.reverse_first) or (index == segments - 1 and plan.reverse_last)


def path_motion(
    base: DiffDriveBase,
    plan: Plan,
    goal_yaw: float,
    *,
    speed: float | None = None,
    name: str = "drive",
) -> SequenceMotion:
    """A motion driving the plan's segments in turn and ending at (last waypoint, goal_yaw); `speed`
    None: the base's limit."""
    speed = active_limits().linear_speed if speed is None else speed
    points = plan.waypoints
    segments = len(points) - 1
    reverse = [_reversed(plan, index, segments) for index in range(segments)]
    headings = [_bearing(points[i], points[i + 1], reverse[i]) for i in range(segments)]
    end_yaws = [*headings[1:], goal_yaw]
    _, _, yaw = base.estimate()
    estimates_s = segment_durations_s(yaw, points, headings, goal_yaw, speed)
    stages = []
    for index in range(segments):
        length = math.dist(points[index], points[index + 1])
        estimate_s = estimates_s[index]

        def drive(index: int = index) -> DriveMotion:
            x, y = points[index + 1]
            return DriveMotion(base, x, y, end_yaws[index], reverse=reverse[index], speed=speed, name=name)

        stages.append((f"driving segment {index + 1}/{segments}", drive, length + TURN_WEIGHT_M, estimate_s))
    return SequenceMotion(name, stages, frozenset({"base"}))
