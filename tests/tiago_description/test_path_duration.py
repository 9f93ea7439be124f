"""A planned path's duration by the drive's rule, however densely the planner spaced its poses.

Why: the skills time the drive after an undock from the navigation stack's plan before it is driven;
the twin's planner hands out its corners only, Nav2's planners a pose per map cell. Both must give
the time the drive takes, segment by segment, as path following times it (segment_durations_s).
"""

from __future__ import annotations

import math

import pytest

from tiago_description.drive_timing import drive_duration_s, path_duration_s, segment_durations_s
from tiago_description.robot_limits import active_limits

CORNERS = ((0.0, 0.0), (2.0, 0.0), (2.0, 1.5))
GOAL_YAW = math.pi


def corner_path() -> list[tuple[float, float, float]]:
    """An L-shaped path as the twin's planner hands it out: corners with the heading driven from them."""
    return [(0.0, 0.0, 0.0), (2.0, 0.0, math.pi / 2), (2.0, 1.5, GOAL_YAW)]


def dense_path(spacing_m: float = 0.05) -> list[tuple[float, float, float]]:
    """The same path with a pose every `spacing_m`, as a grid planner hands it out."""
    poses = []
    for (x0, y0), (x1, y1) in zip(CORNERS, CORNERS[1:], strict=False):
        heading = math.atan2(y1 - y0, x1 - x0)
        steps = round(math.dist((x0, y0), (x1, y1)) / spacing_m)
        poses += [(x0 + (x1 - x0) * k / steps, y0 + (y1 - y0) * k / steps, heading) for k in range(steps)]
    return [*poses, (*CORNERS[-1], GOAL_YAW)]


def test_a_path_takes_its_segments_driven_rest_to_rest() -> None:
    speed = active_limits().linear_speed
    start_yaw = -0.4
    expected = drive_duration_s(0.4, 2.0, math.pi / 2, speed) + drive_duration_s(0.0, 1.5, math.pi / 2, speed)
    assert path_duration_s(start_yaw, corner_path()) == pytest.approx(expected)
    segments = segment_durations_s(start_yaw, CORNERS, [0.0, math.pi / 2], GOAL_YAW, speed)
    assert sum(segments) == pytest.approx(expected)


def test_a_dense_path_takes_as_long_as_its_corners() -> None:
    assert path_duration_s(0.0, dense_path()) == pytest.approx(path_duration_s(0.0, corner_path()))


def test_a_path_of_one_pose_takes_no_time() -> None:
    assert path_duration_s(0.0, [(1.0, 1.0, 0.0)]) == 0.0
