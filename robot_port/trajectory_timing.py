"""How a joint trajectory controller of the port times a JointTrajectory (robot_port.types).

Why here: the timing is part of what a JointTrajectory means. The simulator's controllers run the
path by it, and an adapter that drives a robot's own controllers (which take points with times)
samples the same path into timed points, so a trajectory takes the same time on either.

The rule: every segment as fast as the joints' velocity limits scaled by ``speed_scale`` allow, and
no shorter than ``min_segment_s``; the whole path under one trapezoidal speed profile from rest to
rest that ramps over RAMP_S / speed_scale. Why a trapezoid and not a quintic blend: a quintic's
peak speed is 1.875 times its mean, so timing it within the velocity limits nearly doubles every
move; a trapezoid cruises at the limit. Pure arithmetic on numpy arrays.
"""

from __future__ import annotations

import bisect
from collections.abc import Mapping, Sequence

import numpy as np

RAMP_S = 0.3  # s from rest to a joint's full speed (and back) at speed scale 1
LEAST_SPEED_SCALE = 0.05


def trapezoid(t: float, total: float, ramp: float) -> tuple[float, float]:
    """Distance along a path and speed fraction at time t of a trapezoidal speed profile.

    The path takes ``total`` seconds at full speed; the speed ramps linearly up and down over
    ``ramp`` seconds (a triangle when the path is shorter than that)."""
    accel = 1.0 / ramp
    t_accel = min(ramp, (total * ramp) ** 0.5)
    cruise_end = total / (accel * t_accel)  # time at which deceleration starts
    duration = cruise_end + t_accel
    t = min(max(t, 0.0), duration)
    peak = accel * t_accel
    if t < t_accel:
        return 0.5 * accel * t * t, accel * t
    if t < cruise_end:
        return 0.5 * accel * t_accel * t_accel + peak * (t - t_accel), peak
    left = duration - t
    return total - 0.5 * accel * left * left, accel * left


def trapezoid_duration(total: float, ramp: float) -> float:
    """How long the profile of `trapezoid` takes for a path of ``total`` seconds at full speed."""
    t_accel = min(ramp, (total * ramp) ** 0.5)
    return total / t_accel * ramp + t_accel


class ProfiledPath:
    """Joint positions through ``points`` (the first: where the joints stand) in straight segments,
    timed by the port's rule. ``sample(t)`` gives positions and velocities at time t."""

    def __init__(
        self,
        points: Sequence[np.ndarray],
        velocity_limits: np.ndarray,
        speed_scale: float = 1.0,
        min_segment_s: float = 0.0,
    ) -> None:
        self.points = [np.asarray(point, dtype=float) for point in points]
        scale = max(min(speed_scale, 1.0), LEAST_SPEED_SCALE)
        limits = np.asarray(velocity_limits, dtype=float) * scale
        durations = [
            max(float(np.max(np.abs(b - a) / limits)), min_segment_s)
            for a, b in zip(self.points[:-1], self.points[1:], strict=True)
        ]
        self.path_length = [float(v) for v in np.cumsum([0.0, *durations])]
        self.ramp_s = RAMP_S / scale
        self.duration = max(trapezoid_duration(self.path_length[-1], self.ramp_s), 1e-3)

    def sample(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        total = self.path_length[-1]
        if total <= 0.0:
            return self.points[-1], np.zeros(len(self.points[-1]))
        along, speed = trapezoid(t, total, self.ramp_s)
        index = min(max(bisect.bisect_right(self.path_length, along) - 1, 0), len(self.points) - 2)
        segment = max(self.path_length[index + 1] - self.path_length[index], 1e-9)
        fraction = min((along - self.path_length[index]) / segment, 1.0)
        a, b = self.points[index], self.points[index + 1]
        return a + (b - a) * fraction, (b - a) / segment * speed


def profiled_path(
    start: Mapping[str, float],
    waypoints: Sequence[Mapping[str, float]],
    velocity_limits: Mapping[str, float],
    speed_scale: float = 1.0,
    min_segment_s: float = 0.0,
) -> tuple[list[str], ProfiledPath]:
    """The joints of ``waypoints`` (the first one's order) and their path from ``start``."""
    names = list(waypoints[0])
    points = [np.array([start[n] for n in names])] + [np.array([w[n] for n in names]) for w in waypoints]
    limits = np.array([velocity_limits[n] for n in names])
    return names, ProfiledPath(points, limits, speed_scale, min_segment_s)
