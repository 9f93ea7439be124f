"""Joint trajectories for torso, arms and head, tracked by the position-controlled joints.

Why: every arm motion (play-motion keyframes, straight tool moves made of IK waypoints) becomes
one piecewise trajectory that the joints track at URDF speeds and efforts. Two kinds share the
tracking and the goal check: the port's (`JointTrajectoryMotion`: the controller times the path
within each joint's velocity limit) and a ROS goal's (`TimedTrajectoryMotion`: every point carries
its time, as a FollowJointTrajectory goal gives it to a joint trajectory controller).
Lives on the sim thread.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from robot_port.trajectory_timing import profiled_path
from tiago_sim.physics.motion import CANCELED, Motion
from tiago_sim.physics.robot_body import RobotBody

SETTLE_TOLERANCE = 0.02  # rad (m for the torso): goal tolerance, as a joint trajectory controller has
SETTLE_TIMEOUT_S = 1.5


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
    """Through ``waypoints`` (dicts of joint targets) from where the joints stand, timed by the port's
    rule (robot_port.trajectory_timing: within ``speed_scale`` of each joint's velocity limit, no
    segment shorter than ``min_segment_s``, one trapezoidal speed profile)."""

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
        limits = {n: body.limits[n][2] for n in waypoints[0]}
        self.names, self.path = profiled_path(
            body.joint_positions(), waypoints, limits, speed_scale, min_segment_s
        )
        self.goal = self.path.points[-1]
        self.duration = self.path.duration

    def _sample(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        return self.path.sample(t)


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
