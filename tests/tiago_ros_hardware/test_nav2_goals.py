"""Nav2's path in the port's terms: each pose with the heading the base drives on from it.

Why: NavFn (Nav2's default planner, TIAGo's too) leaves every pose's orientation but the goal's
unset; timed as given, a path would turn the base to heading 0 at every cell.
"""

from __future__ import annotations

import math

import pytest
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Path

from tiago_ros_hardware.nav2_goals import map_pose, path_poses, path_request


def navfn_path(points: list[tuple[float, float]], goal_yaw: float) -> Path:
    path = Path()
    for x, y in points:
        pose = PoseStamped()
        pose.pose.position.x, pose.pose.position.y = x, y
        pose.pose.orientation.w = 1.0  # unset
        path.poses.append(pose)
    path.poses[-1] = map_pose((*points[-1], goal_yaw))
    return path


def test_unset_orientations_become_the_bearing_to_the_next_pose() -> None:
    poses = path_poses(navfn_path([(0.0, 0.0), (0.0, 0.05), (0.05, 0.05)], math.pi))
    assert [p[2] for p in poses] == pytest.approx([math.pi / 2, 0.0, math.pi])


def test_set_orientations_are_kept_and_the_request_plans_from_its_start() -> None:
    path = Path(poses=[map_pose((0.0, 0.0, 3.0)), map_pose((1.0, 0.0, -1.0))])
    assert [p[2] for p in path_poses(path)] == pytest.approx([3.0, -1.0])
    request = path_request((1.0, 2.0, 0.5), (3.0, 4.0, -0.5))
    assert request.use_start and request.start.header.frame_id == request.goal.header.frame_id == "map"
    assert (request.start.pose.position.x, request.goal.pose.position.y) == (1.0, 4.0)
