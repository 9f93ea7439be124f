"""How long the base takes for a drive, as DriveMotion drives it: the estimates behind a drive's
remaining time (navigation's feedback, the SiLA commands' remaining time), and a planned path's
duration before it is driven (the skills' estimate of the drive after an undock).

Why apart from the controller: the timing is plain arithmetic over TIAGo's limits and the control
law's shape (speeding up at the base's limit, braking at 80 % of it, the turn handing over to the
drive at BLEND_ANGLE), shared by path following, docking, the time budget's minima and the skills.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from tiago_description.robot_limits import active_limits
from tiago_description.transforms import wrap_angle

BLEND_ANGLE = 0.3  # rad: the drive starts once the heading is this close; the heading loop finishes the turn
# Of the base's acceleration limit: the control law brakes at this, so the ramp has room to follow.
BRAKING_SHARE = 0.8


def rest_to_rest_s(amount: float, accel: float, max_speed: float) -> float:
    """Time to cover `amount` (m or rad) from rest to rest with a trapezoidal speed profile."""
    return profile_s(amount, accel, accel, max_speed)


def profile_s(
    amount: float,
    accel_up: float,
    accel_down: float,
    max_speed: float,
    start_speed: float = 0.0,
    stop_short: float = 0.0,
) -> float:
    """Time to cover `amount` (m or rad) less `stop_short`, starting at `start_speed` (towards the
    goal), speeding up at `accel_up` to at most `max_speed` and braking at `accel_down` so as to stop
    at `amount`: the law DriveMotion commands (speed from the distance left) under the base's ramp."""
    amount, start = abs(amount), max(start_speed, 0.0)
    covered = amount - stop_short
    if covered <= 0.0:
        return 0.0
    if start * start / (2.0 * accel_down) >= amount:  # already braking: constant deceleration
        return (
            2.0 * covered / max(start + math.sqrt(max(start * start - 2.0 * accel_down * covered, 0.0)), 1e-9)
        )
    peak = min(
        max_speed,
        math.sqrt(
            (amount + start * start / (2.0 * accel_up)) / (1.0 / (2.0 * accel_up) + 1.0 / (2.0 * accel_down))
        ),
    )
    speeding = (peak * peak - start * start) / (2.0 * accel_up)
    braking = peak * peak / (2.0 * accel_down)
    cruise = max(amount - speeding - braking, 0.0)
    if covered <= speeding:
        return (math.sqrt(start * start + 2.0 * accel_up * covered) - start) / accel_up
    if covered <= speeding + cruise:
        return (peak - start) / accel_up + (covered - speeding) / peak
    end_speed = math.sqrt(2.0 * accel_down * min(stop_short, braking))
    return (peak - start) / accel_up + cruise / peak + (peak - end_speed) / accel_down


def _turn_s(angle: float, start_speed: float, stop_short: float = 0.0) -> float:
    """A turn on the spot: speeding up at the angular limit, braking at 80 % of it."""
    limits = active_limits()
    accel = limits.angular_accel
    return profile_s(angle, accel, accel * BRAKING_SHARE, limits.angular_speed, start_speed, stop_short)


SETTLE_S = 0.1
"""s: the heading loop closes its last millimetres and milliradians (about 0.05 s at a drive's end;
counted once per segment, so more here makes every segment's estimate that much long)."""


def drive_duration_s(
    turn_rad: float,
    distance_m: float,
    align_rad: float,
    speed: float,
    linear_speed: float = 0.0,
    angular_speed: float = 0.0,
) -> float:
    """How long a drive takes with TIAGo's limits, as DriveMotion drives: turn to the bearing until
    BLEND_ANGLE is left (the drive then closes the rest), drive, turn to the goal heading; speeding
    up at the base's limits and braking at 80 % of them. `linear_speed` and `angular_speed` are the
    base's speeds now, towards the phase under way (the drive or the turn to the bearing)."""
    moving = distance_m > 0.0
    turning = _turn_s(turn_rad, angular_speed if turn_rad else 0.0, BLEND_ANGLE if moving else 0.0)
    driving = profile_s(
        distance_m,
        active_limits().linear_accel,
        active_limits().linear_accel * BRAKING_SHARE,
        speed,
        start_speed=linear_speed,
    )
    aligning = _turn_s(align_rad, 0.0 if moving or turn_rad else angular_speed)
    return turning + driving + aligning + SETTLE_S


STRAIGHT_RAD = 0.05
"""Poses of a planned path whose headings differ by less than this belong to one straight run (a
planner's dense path: Nav2's poses lie a map cell apart)."""


def segment_durations_s(
    start_yaw: float,
    points: Sequence[tuple[float, float]],
    headings: Sequence[float],
    goal_yaw: float,
    speed: float,
) -> list[float]:
    """How long each straight segment of a path takes, driven rest to rest (DriveMotion): the first
    turns from `start_yaw` to its heading, each ends turned to the next one's heading, the last to
    `goal_yaw`. `headings[i]` is the base's heading while it drives from points[i] to points[i+1]
    (backwards on a reverse segment)."""
    end_yaws = [*headings[1:], goal_yaw]
    durations, before = [], start_yaw
    for index, heading in enumerate(headings):
        length = math.dist(points[index], points[index + 1])
        turn, align = wrap_angle(heading - before), wrap_angle(end_yaws[index] - heading)
        durations.append(drive_duration_s(turn, length, align, speed))
        before = end_yaws[index]
    return durations


def path_duration_s(
    start_yaw: float, path: Sequence[tuple[float, float, float]], speed: float | None = None
) -> float:
    """How long the base takes along a planned path, as the drive makes it: `path` holds poses
    (x, y, the heading the base has driving on from there), the last one the goal with its heading;
    poses that continue a straight run (STRAIGHT_RAD) are one segment. `speed`: the base's limit
    when None."""
    if len(path) < 2:
        return 0.0
    points, headings = [path[0][:2]], [path[0][2]]
    for pose in path[1:-1]:
        if abs(wrap_angle(pose[2] - headings[-1])) >= STRAIGHT_RAD:
            points.append(pose[:2])
            headings.append(pose[2])
    points.append(path[-1][:2])
    limit = active_limits().linear_speed if speed is None else speed
    return sum(segment_durations_s(start_yaw, points, headings, path[-1][2], limit))
