"""The least time TIAGo++'s limits allow for a motion: a joint-space move, a drive, the gripper.

Why: to see where a transfer's time goes, each step's robot time is set against what the robot's
limits would allow for what the step actually moved (joint readings and the base's pose before and
after). The gap is slack some step could win back; the minimum itself no software can beat.
The limits are the robot model's (tiago_description), the joint ramp the trajectory controller's
(robot_port.trajectory_timing). Pure functions.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence

from robot_port.trajectory_timing import RAMP_S, trapezoid_duration
from tiago_description.drive_timing import rest_to_rest_s
from tiago_description.robot_limits import active_limits
from tiago_sim.physics.base_controller import wrap_angle

FINGER_PREFIX = "gripper_"  # finger joints move with the gripper command, not on a trajectory
SHORTEST_SEGMENT_M = 0.001  # a drive's segment shorter than this is no segment


def joint_move_min_s(
    start: Mapping[str, float], end: Mapping[str, float], limits: Mapping[str, float], ramp_s: float = RAMP_S
) -> tuple[float, str]:
    """Least time for one joint-space move from rest to rest, and the joint that sets it.

    The slowest joint's distance at its velocity limit, under the trapezoidal profile the
    controller times every trajectory with (``ramp_s`` from rest to full speed). Joints without a
    limit in ``limits`` do not count."""
    slowest, name = 0.0, ""
    for joint in start.keys() & end.keys() & limits.keys():
        seconds = abs(end[joint] - start[joint]) / limits[joint]
        if seconds > slowest:
            slowest, name = seconds, joint
    if slowest <= 0.0:
        return 0.0, ""
    return trapezoid_duration(slowest, ramp_s), name


def gripper_min_s(start: Mapping[str, float], end: Mapping[str, float], speed: float | None = None) -> float:
    """Least time for the fingers' travel at their speed limit (the longer finger's travel); `speed`
    None: the fingers' limit."""
    speed = active_limits().finger_speed if speed is None else speed
    travel = max((abs(end[j] - start[j]) for j in start.keys() & end.keys()), default=0.0)
    return travel / speed


def drive_min_s(
    path: Sequence[tuple[float, float]], start_yaw: float, end_yaw: float
) -> tuple[float, float, float]:
    """Least time to drive along ``path`` (points in m) from heading ``start_yaw`` to ``end_yaw``,
    with the path length and the angle turned: (seconds, metres, radians).

    The length as one profile from rest to rest at the linear speed and acceleration limits, the
    turns (onto each segment, then onto the end heading) as one at the angular limits, and the
    longer of the two: the base may turn while it drives, each axis within its own limits (the
    path following drives each segment from rest to rest at 80 % of them and turns on the spot at
    the corners). A segment may be driven backwards where that turns less (undocking does)."""
    legs = list(_legs(path, start_yaw))
    heading = start_yaw + sum(turn for _, turn in legs)
    turned = sum(abs(turn) for _, turn in legs) + abs(wrap_angle(end_yaw - heading))
    length = sum(segment for segment, _ in legs)
    limits = active_limits()
    driving = rest_to_rest_s(length, limits.linear_accel, limits.linear_speed) if length > 0 else 0.0
    turning = rest_to_rest_s(turned, limits.angular_accel, limits.angular_speed) if turned > 0 else 0.0
    return max(driving, turning), length, turned


def _legs(path: Sequence[tuple[float, float]], start_yaw: float) -> Iterator[tuple[float, float]]:
    """(segment length, turn onto it) along the path, each segment forwards or backwards, whichever
    turns less from the heading before it."""
    heading = start_yaw
    for (x0, y0), (x1, y1) in zip(path[:-1], path[1:], strict=False):
        segment = math.hypot(x1 - x0, y1 - y0)
        if segment < SHORTEST_SEGMENT_M:
            continue
        bearing = math.atan2(y1 - y0, x1 - x0)
        forward, backward = wrap_angle(bearing - heading), wrap_angle(bearing + math.pi - heading)
        turn = forward if abs(forward) <= abs(backward) else backward
        heading += turn
        yield segment, turn


def split_joints(joints: Mapping[str, float]) -> tuple[dict[str, float], dict[str, float]]:
    """Trajectory joints (arms, torso, head) and finger joints, apart."""
    fingers = {name: value for name, value in joints.items() if name.startswith(FINGER_PREFIX)}
    return {name: value for name, value in joints.items() if name not in fingers}, fingers
