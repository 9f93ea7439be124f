"""Differential-drive base: velocity actuator with TIAGo's limits, wheel odometry, drive motions.

Why this shape: the base is kinematic in the plane (a constraint follows the integrated,
speed- and acceleration-limited body velocity), which is stable in PyBullet and honours the
real drive's limits. The wheel encoders see the base's real motion with a seeded scale error and
noise per wheel, so odometry drifts like a real robot's; drive motions close the loop on
the pose estimate (odometry plus localisation's correction). Lives on the sim thread.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from lab_description.world import Pose2D
from tiago_description import robot_model as rm
from tiago_description.drive_timing import BLEND_ANGLE, BRAKING_SHARE, drive_duration_s
from tiago_description.robot_limits import active_limits
from tiago_description.transforms import compose_planar as compose
from tiago_description.transforms import invert_planar as invert
from tiago_sim.physics.motion import CANCELED, Motion, SequenceMotion
from tiago_sim.physics.robot_body import RobotBody

POSITION_TOLERANCE = 0.01  # m
YAW_TOLERANCE = 0.01  # rad
HEADING_GAIN = 2.5
# How fast localisation's correction may move the believed pose while a drive runs: a typical
# correction (under 1 cm, 0.3 deg) is in within 0.2 s; a large one is spread over seconds, which
# the drive's heading loop (gain 2.5 /s) follows without a kink. At rest it applies at once.
CORRECTION_SPEED = 0.05  # m/s
CORRECTION_TURN_RATE = 0.03  # rad/s


def wrap_angle(angle: float) -> float:
    """Angle wrapped to (-pi, pi] (scalar, fast: called every step)."""
    return math.atan2(math.sin(angle), math.cos(angle))


def _ramp(current: float, desired: float, max_change: float) -> float:
    return current + min(max(desired - current, -max_change), max_change)


def _speed_for_distance(distance: float, accel: float, max_speed: float) -> float:
    """Largest speed from which the remaining distance suffices to stop."""
    return min(max_speed, math.sqrt(2.0 * accel * max(distance, 0.0)))


class DiffDriveBase:
    """Body-velocity actuator plus wheel odometry."""

    def __init__(
        self, body: RobotBody, x: float, y: float, yaw: float, odometry_noise: float, rng: np.random.Generator
    ) -> None:
        self.body = body
        self.target = [x, y, yaw]  # pose the base constraint pulls towards
        self.v = 0.0
        self.w = 0.0
        self.v_cmd = 0.0
        self.w_cmd = 0.0
        self.odom = [x, y, yaw]
        self.last_true = (x, y, yaw)
        self.idle_steps = 0
        self.noise = odometry_noise
        self.rng = rng
        # per-wheel radius errors (calibration), drawn once: the systematic part of odometry drift
        self.wheel_scale = 1.0 + odometry_noise * rng.standard_normal(2)
        # localisation's correction (x, y, yaw of the odometry frame in the map); identity until a
        # localiser sets it. Drives close their loop on ``estimate()``, never on raw odometry.
        self.map_from_odom = (0.0, 0.0, 0.0)
        self.map_from_odom_target: tuple[float, float, float] | None = None  # see correct()
        self.driven = False  # a base motion runs (Simulation.step sets it every step)
        self.hold_correction = False  # set every step by a drive whose goal is relative to its start

    def estimate(self) -> tuple[float, float, float]:
        """The base's pose in the map as the robot believes it: odometry with localisation's correction."""
        ox, oy, oyaw = self.odom
        return compose(self.map_from_odom, (ox, oy, oyaw))

    def correct(self, map_from_odom: tuple[float, float, float]) -> None:
        """Localisation's new correction. Applied by ``update``: at once while no drive runs,
        rate-limited while one does, not at all during a relative drive (undock, the marker-guided
        final approach: their goal was measured from where the base stood, and a shift of the
        map frame under them would move the goal off what was measured)."""
        self.map_from_odom_target = tuple(float(v) for v in map_from_odom)  # type: ignore[assignment]

    def _apply_correction(self, dt: float) -> None:
        target, hold = self.map_from_odom_target, self.hold_correction
        self.hold_correction = False
        if target is None or hold:
            return
        if not self.driven:
            self.map_from_odom, self.map_from_odom_target = target, None
            return
        # limit how far the believed base pose moves this step, then re-derive the frame from it
        ox, oy, oyaw = self.odom
        x, y, yaw = compose(self.map_from_odom, (ox, oy, oyaw))
        tx, ty, tyaw = compose(target, (ox, oy, oyaw))
        shift = math.hypot(tx - x, ty - y)
        scale = min(1.0, CORRECTION_SPEED * dt / shift) if shift > 0.0 else 1.0
        turn = wrap_angle(tyaw - yaw)
        turn = min(max(turn, -CORRECTION_TURN_RATE * dt), CORRECTION_TURN_RATE * dt)
        believed = (x + scale * (tx - x), y + scale * (ty - y), yaw + turn)
        self.map_from_odom = compose(believed, invert((ox, oy, oyaw)))
        if scale >= 1.0 and abs(wrap_angle(tyaw - yaw)) <= CORRECTION_TURN_RATE * dt:
            self.map_from_odom, self.map_from_odom_target = target, None

    def command(self, v: float, w: float) -> None:
        limits = active_limits()
        self.v_cmd = min(max(v, -limits.linear_speed), limits.linear_speed)
        self.w_cmd = min(max(w, -limits.angular_speed), limits.angular_speed)

    def protective_stop(self) -> None:
        """Cut the drive at once (a collision): velocity and command zero, the base held where it
        stands. A real base's protective stop brakes far beyond the 0.5 m/s^2 of normal driving;
        braking at that rate from 1 m/s would carry the robot 1 m on into what it hit."""
        self.v = self.w = self.v_cmd = self.w_cmd = 0.0
        self.target = list(self.body.base_xy_yaw())
        self.body.set_base_target(*self.target)

    def stopped(self) -> bool:
        """The command has ramped to zero and the base itself stands still (it lags the command,
        so a drive that reports "stopped" on the command alone would still be rolling)."""
        if abs(self.v) >= 1e-3 or abs(self.w) >= 1e-3:
            return False
        forward, turn = self.body.base_twist()
        return abs(forward) < 0.005 and abs(turn) < 0.01

    def update(self, dt: float) -> None:
        """Before the physics step: accelerate towards the command and move the constraint pivot."""
        limits = active_limits()
        self.v = _ramp(self.v, self.v_cmd, limits.linear_accel * dt)
        self.w = _ramp(self.w, self.w_cmd, limits.angular_accel * dt)
        x, y, yaw = self.target
        mid_yaw = yaw + 0.5 * self.w * dt
        self.target = [
            x + self.v * math.cos(mid_yaw) * dt,
            y + self.v * math.sin(mid_yaw) * dt,
            yaw + self.w * dt,
        ]
        if self.v != 0.0 or self.w != 0.0:
            self.body.set_base_target(*self.target)
        self._apply_correction(dt)

    def integrate_odometry(self, dt: float) -> None:
        """After the physics step: wheel encoders count the base's real displacement, with error."""
        moving = self.v != 0.0 or self.w != 0.0 or self.v_cmd != 0.0 or self.w_cmd != 0.0
        self.idle_steps = 0 if moving else self.idle_steps + 1
        if self.idle_steps > 240:  # stood still for a second: the encoders read nothing, skip the work
            return
        x, y, yaw = self.body.base_xy_yaw()
        last_x, last_y, last_yaw = self.last_true
        self.last_true = (x, y, yaw)
        heading = last_yaw + 0.5 * wrap_angle(yaw - last_yaw)
        forward = (x - last_x) * math.cos(heading) + (y - last_y) * math.sin(heading)
        turn = wrap_angle(yaw - last_yaw)
        half = rm.WHEEL_SEPARATION / 2
        wheel_left = forward - turn * half  # wheel travel in m this step
        wheel_right = forward + turn * half
        if self.noise > 0.0 and (abs(wheel_left) + abs(wheel_right)) > 1e-7:
            jitter_left, jitter_right = self.rng.standard_normal(2).tolist()
            wheel_left *= self.wheel_scale[0] * (1.0 + self.noise * jitter_left)
            wheel_right *= self.wheel_scale[1] * (1.0 + self.noise * jitter_right)
        distance = (wheel_left + wheel_right) / 2
        rotation = (wheel_right - wheel_left) / rm.WHEEL_SEPARATION
        ox, oy, oyaw = self.odom
        mid_yaw = oyaw + 0.5 * rotation
        self.odom = [
            ox + distance * math.cos(mid_yaw),
            oy + distance * math.sin(mid_yaw),
            wrap_angle(oyaw + rotation),
        ]


class DriveMotion(Motion):
    """Turn towards the goal, drive, then turn to the goal heading; closed loop on the pose estimate.

    ``reverse`` drives backwards (for docking); ``stop_when`` ends the drive early with success
    (e.g. the dock contact closes).
    """

    def __init__(
        self,
        base: DiffDriveBase,
        x: float,
        y: float,
        yaw: float,
        *,
        reverse: bool = False,
        speed: float | None = None,
        stop_when=None,
        name: str = "drive",
        relative: bool = False,
    ) -> None:
        super().__init__(name, frozenset({"base"}))
        self.base = base
        self.relative = relative  # the goal was measured from where the base stood: hold the map frame
        self.goal = (x, y, yaw)
        self.reverse = reverse
        self.speed = active_limits().linear_speed if speed is None else speed  # None: the base's limit
        self.stop_when = stop_when
        self.phase = "turning"
        self.start_distance = max(self._distance(), 1e-6)
        self.remaining_s = self._estimate_remaining_s(self._distance())

    def _distance(self) -> float:
        x, y, _ = self.base.estimate()
        return math.hypot(self.goal[0] - x, self.goal[1] - y)

    def _heading_error(self) -> float:
        x, y, yaw = self.base.estimate()
        bearing = math.atan2(self.goal[1] - y, self.goal[0] - x)
        if self.reverse:
            bearing += math.pi
        return wrap_angle(bearing - yaw)

    def _estimate_remaining_s(self, distance: float) -> float:
        """What is left of the drive in the current phase and after it, from TIAGo's limits."""
        x, y, yaw = self.base.estimate()
        moving = distance > POSITION_TOLERANCE * 2
        bearing = math.atan2(self.goal[1] - y, self.goal[0] - x) + (math.pi if self.reverse else 0.0)
        if self.phase == "aligning" or not moving:
            error = wrap_angle(self.goal[2] - yaw)
            towards = math.copysign(1.0, error) * self.base.w
            return drive_duration_s(0.0, 0.0, error, self.speed, angular_speed=towards)
        align = wrap_angle(self.goal[2] - bearing)
        if self.phase == "turning":
            turn = wrap_angle(bearing - yaw)
            towards = math.copysign(1.0, turn) * self.base.w
            return drive_duration_s(turn, distance, align, self.speed, angular_speed=towards)
        forwards = -self.base.v if self.reverse else self.base.v
        return drive_duration_s(0.0, distance, align, self.speed, linear_speed=forwards)

    def _turn_rate(self, error: float) -> float:
        return math.copysign(
            _speed_for_distance(
                abs(error), active_limits().angular_accel * BRAKING_SHARE, active_limits().angular_speed
            ),
            error,
        )

    def tick(self, dt: float) -> None:
        base = self.base
        base.hold_correction = base.hold_correction or self.relative
        if self.cancel_requested:
            base.command(0.0, 0.0)
            self.phase = "stopping"
            if base.stopped():
                self.finish(False, CANCELED, "canceled")
            return
        if self.stop_when is not None and self.stop_when():
            base.command(0.0, 0.0)
            if base.stopped():
                self.finish(True, message="contact")
            return
        distance = self._distance()
        self.progress = float(np.clip(1.0 - distance / self.start_distance, 0.0, 0.99))
        self.remaining_s = self._estimate_remaining_s(distance)
        if self.phase == "turning":
            error = self._heading_error() if distance > POSITION_TOLERANCE * 2 else 0.0
            base.command(0.0, self._turn_rate(error))
            if distance > POSITION_TOLERANCE * 2 and abs(error) < BLEND_ANGLE:
                self.phase = "driving"  # v ramps up from rest while the heading loop closes the error
            elif abs(error) < 0.02 and abs(base.w) < 0.05:
                self.phase = "aligning"
        elif self.phase == "driving":
            direction = -1.0 if self.reverse else 1.0
            heading_error = self._heading_error()
            along = distance * math.cos(heading_error)
            v = direction * _speed_for_distance(
                along, active_limits().linear_accel * BRAKING_SHARE, self.speed
            )
            if along < POSITION_TOLERANCE * 0.5 or distance < POSITION_TOLERANCE * 0.5:
                v = 0.0
                if base.stopped() or abs(base.v) < 0.02:
                    self.phase = "aligning"
            w = HEADING_GAIN * heading_error if distance > 0.05 else 0.0
            base.command(v, w)
        else:  # aligning
            error = wrap_angle(self.goal[2] - base.estimate()[2])
            within = abs(error) < YAW_TOLERANCE * 0.5
            base.command(0.0, 0.0 if within else self._turn_rate(error))
            if within and base.stopped():
                if self.stop_when is not None:
                    self.finish(False, "NAVIGATION_FAILED", "reached the end of the path without contact")
                else:
                    self.finish(True)

    def finish(self, success: bool, error_code: str = "", message: str = "") -> None:
        self.base.command(0.0, 0.0)
        super().finish(success, error_code, message)


DOCK_SPEED = 0.05  # m/s backing onto the dock: stops within 3 mm once the contacts close
DOCK_OVERTRAVEL = 0.08  # m: the reverse drive aims this far past the docked pose, contact ends it


def docking_motion(
    base: DiffDriveBase, approach: Pose2D, dock: Pose2D, docked: Callable[[], bool]
) -> SequenceMotion:
    """Drive to the dock's approach pose, then back onto the dock slowly until `docked()` (the
    charging contacts) says so; each stage with its time estimate, so the remaining time counts
    the slow last stretch from the start."""
    beyond = (dock.x - DOCK_OVERTRAVEL * math.cos(dock.yaw), dock.y - DOCK_OVERTRAVEL * math.sin(dock.yaw))
    x, y, yaw = base.estimate()
    bearing = math.atan2(approach.y - y, approach.x - x)
    approach_s = drive_duration_s(
        wrap_angle(bearing - yaw),
        math.hypot(approach.x - x, approach.y - y),
        wrap_angle(approach.yaw - bearing),
        active_limits().linear_speed,
    )
    docking_s = drive_duration_s(0.0, math.hypot(dock.x - approach.x, dock.y - approach.y), 0.0, DOCK_SPEED)

    def back_onto_dock() -> DriveMotion:
        return DriveMotion(
            base, *beyond, dock.yaw, reverse=True, speed=DOCK_SPEED, stop_when=docked, name="dock_in"
        )

    stages = [
        ("approach", lambda: DriveMotion(base, approach.x, approach.y, approach.yaw), 0.7, approach_s),
        ("docking", back_onto_dock, 0.3, docking_s),
    ]
    return SequenceMotion("dock", stages, frozenset({"base"}))


class VelocityMotion(Motion):
    """The base at a commanded twist for a while, as a velocity command on /cmd_vel drives it:
    accelerating within the base's limits, then braking to a stand at the end or on a cancel."""

    def __init__(self, base: DiffDriveBase, linear: float, angular: float, duration_s: float) -> None:
        super().__init__("velocity", frozenset({"base"}))
        self.base = base
        self.linear, self.angular = linear, angular
        self.duration_s = max(duration_s, 0.0)
        self.phase = "driving"
        self.remaining_s = self.duration_s

    def renew(self, linear: float, angular: float, duration_s: float) -> bool:
        """A new command before this one ran out: the new twist, for `duration_s` from now, without
        braking between (a velocity topic's next message). False once braking has begun."""
        if self.done or self.cancel_requested or self.elapsed_s >= self.duration_s:
            return False
        self.linear, self.angular = linear, angular
        self.duration_s = self.elapsed_s + max(duration_s, 0.0)
        return True

    def tick(self, dt: float) -> None:
        braking = self.cancel_requested or self.elapsed_s >= self.duration_s
        if braking:
            self.base.command(0.0, 0.0)
            self.phase = "stopping"
            if self.base.stopped():
                if self.cancel_requested:
                    self.finish(False, CANCELED, "canceled")
                else:
                    self.finish(True)
            return
        self.base.command(self.linear, self.angular)
        self.progress = min(self.elapsed_s / max(self.duration_s, 1e-9), 1.0)
        self.remaining_s = self.duration_s - self.elapsed_s
