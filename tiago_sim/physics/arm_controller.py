"""Joint trajectories for torso, arms and head, tracked by the position-controlled joints.

Why: every arm motion (play-motion keyframes, straight tool moves made of IK waypoints) becomes
one piecewise trajectory that the joints track at URDF speeds and efforts. Two kinds share the
tracking and the goal check: the port's (`JointTrajectoryMotion`: the controller times the path
within each joint's velocity limit) and a ROS goal's (`TimedTrajectoryMotion`: every point carries
its time, as a FollowJointTrajectory goal gives it to a joint trajectory controller).
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


class TrackedTrajectory(Motion):
    """Joints tracking a path sampled in time, then settling within SETTLE_TOLERANCE of its end.
    Subclasses set `names`, `goal` (the last point), `duration` and `_sample(t)`."""

    names: list[str]
    goal: np.ndarray
    duration: float

    def __init__(self, body: RobotBody, name: str, resources: frozenset[str]) -> None:
        super().__init__(name, resources)
        self.body = body
        self.phase = "moving"
        self.settle_s = 0.0

    def _sample(self, t: float) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - abstract
        raise NotImplementedError

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
        errors = np.abs(np.array([here[n] for n in self.names]) - self.goal)
        error = float(np.max(errors))
        if error < SETTLE_TOLERANCE:
            self.finish(True)
        elif self.settle_s > SETTLE_TIMEOUT_S:
            # the joint furthest off names the blocked part of the robot (rad; m for the torso)
            worst = self.names[int(np.argmax(errors))]
            self.finish(False, "MOTION_FAILED", f"joints did not reach the goal (error {error:.3f}, {worst})")


class JointTrajectoryMotion(TrackedTrajectory):
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
        super().__init__(body, name, resources)
        self.names = list(waypoints[0])
        start = body.joint_positions()
        self.points = [np.array([start[n] for n in self.names])]
        self.points += [np.array([wp[n] for n in self.names]) for wp in waypoints]
        self.goal = self.points[-1]
        scale = max(min(speed_scale, 1.0), 0.05)
        limits = np.array([body.limits[n][2] for n in self.names]) * scale
        durations = []
        for a, b in zip(self.points[:-1], self.points[1:], strict=True):
            durations.append(max(float(np.max(np.abs(b - a) / limits)), min_segment_s))
        self.path_length = [float(v) for v in np.cumsum([0.0, *durations])]
        self.ramp_s = RAMP_S / scale
        self.duration = max(_trapezoid_duration(self.path_length[-1], self.ramp_s), 1e-3)

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


class TimedTrajectoryMotion(TrackedTrajectory):
    """Through points that each carry their time from the start, as a joint trajectory controller
    runs a FollowJointTrajectory goal: from where the joints stand to the first point, then point to
    point, cubic where the points give velocities (the path then passes each point at its velocity)
    and linear where they do not. The caller has checked the goal (increasing times, sizes)."""

    def __init__(
        self,
        body: RobotBody,
        names: Sequence[str],
        times_s: Sequence[float],
        positions: Sequence[Sequence[float]],
        velocities: Sequence[Sequence[float]] | None = None,
        name: str = "follow_joint_trajectory",
        resources=frozenset(),
    ) -> None:
        super().__init__(body, name, resources)
        self.names = list(names)
        start = body.joint_positions()
        self.times = np.array([0.0, *times_s])
        self.points = np.array([[start[n] for n in self.names], *positions], dtype=float)
        self.velocities = (
            None if velocities is None else np.array([np.zeros(len(self.names)), *velocities], dtype=float)
        )
        self.goal = self.points[-1]
        self.duration = max(float(self.times[-1]), 1e-3)

    def _sample(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        if t >= self.times[-1]:
            return self.points[-1], np.zeros(len(self.names))
        index = int(np.searchsorted(self.times, t, side="right")) - 1
        t0, t1 = self.times[index], self.times[index + 1]
        span = max(t1 - t0, 1e-9)
        a, b = self.points[index], self.points[index + 1]
        if self.velocities is None:
            return a + (b - a) * (t - t0) / span, (b - a) / span
        va, vb = self.velocities[index] * span, self.velocities[index + 1] * span  # per unit of s
        s = (t - t0) / span
        h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
        d00, d10, d01, d11 = 6 * s**2 - 6 * s, 3 * s**2 - 4 * s + 1, -6 * s**2 + 6 * s, 3 * s**2 - 2 * s
        position = h00 * a + h10 * va + h01 * b + h11 * vb
        velocity = (d00 * a + d10 * va + d01 * b + d11 * vb) / span
        return position, velocity
