"""The base commands the port offers that a robot has no action for, closed by the adapter over the
velocity command and odometry: a twist held for a while, and a short straight drive to a pose.

Why in the adapter: a TIAGo++ takes only velocity commands below Nav2 (twist_mux ->
/mobile_base_controller/cmd_vel_unstamped), and each command lasts 0.5 s of robot time unless
renewed. So the loops renew it every PUBLISH_PERIOD_S of wall time, which holds while the robot runs
at most about ten times faster than the wall (a simulator paced at --realtime-factor-cap). The
drive steers along the line to the goal and turns to its heading at the end, within the tolerances
below. Runs on the execution's own thread.
"""

from __future__ import annotations

import math
import time
from typing import Any

PUBLISH_PERIOD_S = 0.05
"""Wall seconds between velocity commands."""
STOPPED_MPS = 0.005
STOPPED_RADPS = 0.01
STOP_TIMEOUT_S = 20.0
POSITION_TOLERANCE_M = 0.01  # the simulator's own drive stops within these too
YAW_TOLERANCE_RAD = 0.01
DRIVE_GAIN = 1.2  # 1/s: the speed asked per metre left
TURN_GAIN = 1.5  # 1/s
MAX_TURN_RADPS = 0.6
FINAL_TURN_GAIN = 0.8  # 1/s: turning on the spot to the heading, against the readings' delay
LEAST_TURN_RADPS = 0.02
DECELERATION = 0.4  # m/s^2, below the base's 0.5
DRIVE_TIMEOUT_S = 60.0  # robot seconds


def _stop(hardware: Any, run: Any) -> tuple:
    """Command zero and wait until odometry shows the base standing."""
    deadline = time.monotonic() + STOP_TIMEOUT_S
    while time.monotonic() < deadline:
        hardware.publish_twist(0.0, 0.0)
        _pose, (linear, angular) = hardware.base_motion()
        if abs(linear) < STOPPED_MPS and abs(angular) < STOPPED_RADPS:
            return (False, "CANCELED", "canceled") if run.cancel_requested else (True,)
        time.sleep(PUBLISH_PERIOD_S)
    return (False, "MOTION_FAILED", f"the base did not stop within {STOP_TIMEOUT_S:g} s")


def velocity_loop(hardware: Any, run: Any, linear: float, angular: float, duration_s: float) -> tuple:
    """The base at (linear, angular) for `duration_s` of robot time, then standing."""
    start = hardware.now()
    while hardware.now() - start < duration_s and not run.cancel_requested:
        hardware.publish_twist(linear, angular)
        time.sleep(PUBLISH_PERIOD_S)
    return _stop(hardware, run)


def drive_loop(hardware: Any, run: Any, goal: tuple[float, float, float], speed: float) -> tuple:
    """To `goal` (x, y, yaw in the odometry frame), forwards or backwards along the line to it, then
    turning on the spot to its heading (once there, it only turns)."""
    start = hardware.now()
    arrived = False
    while not run.cancel_requested:
        (x, y, yaw), _speeds = hardware.next_base_motion()
        dx, dy = goal[0] - x, goal[1] - y
        distance = math.hypot(dx, dy)
        yaw_error = math.remainder(goal[2] - yaw, math.tau)
        arrived = arrived or distance < POSITION_TOLERANCE_M
        if arrived and abs(yaw_error) < YAW_TOLERANCE_RAD:
            break
        if hardware.now() - start > DRIVE_TIMEOUT_S:
            hardware.publish_twist(0.0, 0.0)
            return (
                False,
                "MOTION_FAILED",
                f"the drive did not arrive ({distance:.3f} m, {yaw_error:.3f} rad left)",
            )
        if arrived:  # slowly: each reading is up to a tick old
            turn = max(LEAST_TURN_RADPS, FINAL_TURN_GAIN * abs(yaw_error))
            linear, angular = 0.0, math.copysign(turn, yaw_error)
        else:
            ahead = math.cos(yaw) * dx + math.sin(yaw) * dy
            aside = -math.sin(yaw) * dx + math.cos(yaw) * dy
            direction = 1.0 if ahead >= 0.0 else -1.0
            bearing = math.atan2(direction * aside, direction * ahead)  # of the goal, from the way we face
            along = min(speed, DRIVE_GAIN * distance, math.sqrt(2.0 * DECELERATION * distance))
            linear, angular = direction * along * max(0.0, math.cos(bearing)), TURN_GAIN * bearing
        hardware.publish_twist(linear, max(-MAX_TURN_RADPS, min(MAX_TURN_RADPS, angular)))
        time.sleep(PUBLISH_PERIOD_S)
    return _stop(hardware, run)
