"""Joint trajectories for torso, arms and head: timed within each joint's velocity limit.

Why: every arm motion (play-motion keyframes, straight tool moves made of IK waypoints) becomes
one piecewise trajectory that position-controlled joints track at URDF speeds and efforts.
Lives on the sim thread.
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence

import numpy as np

from tiago_sim.physics.motion import CANCELED, Motion
from tiago_sim.physics.robot_body import RobotBody

SETTLE_TOLERANCE = 0.02  # rad (m for the torso): goal tolerance, as a joint trajectory controller has
SETTLE_TIMEOUT_S = 1.5


RAMP_S = 0.3  # s from rest to a joint's full speed (and back) at speed scale 1


def _trapezoid(t: float, total: float, ramp: float) -> tuple[float, float]:
    """Distance along a path and speed fraction at time t of a trapezoidal speed profile.

    The path takes ``total`` seconds at full speed; the speed ramps linearly up and down over
    ``ramp`` seconds (a triangle when the path is shorter than that). Why not a quintic blend:
    its peak speed is 1.875x its mean, so timing it within the velocity limits nearly doubles
    every move; a trapezoid cruises at the limit.
    """
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


def _trapezoid_duration(total: float, ramp: float) -> float:
    t_accel = min(ramp, (total * ramp) ** 0.5)
    return total / t_accel * ramp + t_accel


class JointTrajectoryMotion(Motion):
    """Through ``waypoints`` (dicts of joint targets): linear segments under one speed profile.

    Segments are timed so no joint exceeds ``speed_scale`` times its limit (or take at least
    ``min_segment_s``); the whole path follows a trapezoidal speed profile, starting and ending at
    rest, ramping over RAMP_S / speed_scale.
    """

    def __init__(
        self,
        body: RobotBody,
        waypoints: Sequence[dict[str, float]],
        speed_scale: float = 1.0,
        name: str = "move_joints",
        min_segment_s: float = 0.0,
        resources=frozenset(),
    ) -> None:
        super().__init__(name, resources)
        self.body = body
        self.names = list(waypoints[0])
        start = body.joint_positions()
        self.points = [np.array([start[n] for n in self.names])]
        self.points += [np.array([wp[n] for n in self.names]) for wp in waypoints]
        scale = max(min(speed_scale, 1.0), 0.05)
        limits = np.array([body.limits[n][2] for n in self.names]) * scale
        durations = []
        for a, b in zip(self.points[:-1], self.points[1:], strict=True):
            durations.append(max(float(np.max(np.abs(b - a) / limits)), min_segment_s))
        self.path_length = [float(v) for v in np.cumsum([0.0, *durations])]
        self.ramp_s = RAMP_S / scale
        self.duration = max(_trapezoid_duration(self.path_length[-1], self.ramp_s), 1e-3)
        self.phase = "moving"
        self.settle_s = 0.0

    def _sample(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        total = self.path_length[-1]
        if total <= 0.0:
            return self.points[-1], np.zeros(len(self.names))
        along, speed = _trapezoid(t, total, self.ramp_s)
        index = min(max(bisect.bisect_right(self.path_length, along) - 1, 0), len(self.points) - 2)
        segment = max(self.path_length[index + 1] - self.path_length[index], 1e-9)
        fraction = min((along - self.path_length[index]) / segment, 1.0)
        a, b = self.points[index], self.points[index + 1]
        return a + (b - a) * fraction, (b - a) / segment * speed

    def tick(self, dt: float) -> None:
        if self.cancel_requested:
            here = self.body.joint_positions()
            self.body.command_positions({n: here[n] for n in self.names})
            self.finish(False, CANCELED, "canceled")
            return
        t = self.elapsed_s
        position, velocity = self._sample(t)
        self.body.track(self.names, position, velocity)
        self.progress = float(min(t / self.duration, 1.0)) * 0.99
        self.remaining_s = max(self.duration - t, 0.0)
        if t < self.duration:
            return
        self.phase = "settling"
        self.settle_s += dt
        here = self.body.joint_positions()
        errors = np.abs(np.array([here[n] for n in self.names]) - self.points[-1])
        error = float(np.max(errors))
        if error < SETTLE_TOLERANCE:
            self.finish(True)
        elif self.settle_s > SETTLE_TIMEOUT_S:
            # the joint furthest off names the blocked part of the robot (rad; m for the torso)
            worst = self.names[int(np.argmax(errors))]
            self.finish(False, "MOTION_FAILED", f"joints did not reach the goal (error {error:.3f}, {worst})")
