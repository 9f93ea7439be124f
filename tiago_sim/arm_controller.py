"""Joint trajectories for torso, arms and head: timed within each joint's velocity limit.

Why: every arm motion (play-motion keyframes, straight tool moves made of IK waypoints) becomes
one piecewise trajectory that position-controlled joints track at URDF speeds and efforts.
Lives on the sim thread.
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence

import numpy as np

from tiago_sim.motion import CANCELED, Motion
from tiago_sim.robot_body import RobotBody

SETTLE_TOLERANCE = 0.02  # rad (m for the torso): goal tolerance, as a joint trajectory controller has
SETTLE_TIMEOUT_S = 1.5


def _smoothstep(s: float) -> tuple[float, float]:
    """Quintic blend (value, derivative) on [0, 1]: zero velocity and acceleration at both ends."""
    s = min(max(s, 0.0), 1.0)
    return s**3 * (10 - 15 * s + 6 * s * s), 30 * s * s * (1 - s) ** 2


class JointTrajectoryMotion(Motion):
    """Through ``waypoints`` (dicts of joint targets); smooth start and stop, linear in between.

    A single waypoint gets a quintic profile (peak speed 1.875x the mean) timed so no joint
    exceeds ``speed_scale`` times its limit; several waypoints are linear segments timed the same
    way and eased in and out as a whole.
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
        limits = np.array([body.limits[n][2] for n in self.names]) * max(min(speed_scale, 1.0), 0.05)
        durations = []
        for a, b in zip(self.points[:-1], self.points[1:], strict=True):
            durations.append(max(float(np.max(np.abs(b - a) / limits)), min_segment_s))
        # easing the whole path in and out costs about the quintic's peak factor on its ends
        total = sum(durations)
        self.path_length = [float(v) for v in np.cumsum([0.0, *durations])]
        self.duration = max(total * 1.875 if len(durations) == 1 else total + 2 * min(0.5, total / 2), 1e-3)
        self.phase = "moving"
        self.settle_s = 0.0

    def _sample(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        total = self.path_length[-1]
        if total <= 0.0:
            return self.points[-1], np.zeros(len(self.names))
        s, ds = _smoothstep(t / self.duration)
        along = s * total
        index = min(max(bisect.bisect_right(self.path_length, along) - 1, 0), len(self.points) - 2)
        segment = max(self.path_length[index + 1] - self.path_length[index], 1e-9)
        fraction = (along - self.path_length[index]) / segment
        a, b = self.points[index], self.points[index + 1]
        velocity = (b - a) / segment * ds * total / self.duration
        return a + (b - a) * fraction, velocity

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
        error = float(np.max(np.abs(np.array([here[n] for n in self.names]) - self.points[-1])))
        if error < SETTLE_TOLERANCE:
            self.finish(True)
        elif self.settle_s > SETTLE_TIMEOUT_S:
            self.finish(False, "MOTION_FAILED", f"joints did not reach the goal (error {error:.3f})")
