"""Nav2's goals and plans in the port's terms: a pose goal in the map frame, a planner request, and
the planner's path as the port's poses.

Why apart: the navigation goal and the planner request carry the same map-frame pose, and the path
Nav2 hands back needs a heading per pose that its planners do not always fill (NavFn leaves the
orientation of every pose but the goal unset).

Threads: `result_of` on any thread but the ones spinning the client's node.
"""

from __future__ import annotations

import math
import threading
from typing import Any

from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped
from nav2_msgs.action import ComputePathToPose

from robot_port.types import Pose2D
from tiago_ros_hardware.frames import yaw_of

MAP_FRAME = "map"


def map_pose(pose: Pose2D) -> PoseStamped:
    """A floor pose (x, y, yaw) as a PoseStamped in the map frame."""
    stamped = PoseStamped()
    stamped.header.frame_id = MAP_FRAME
    stamped.pose.position.x, stamped.pose.position.y = float(pose[0]), float(pose[1])
    stamped.pose.orientation.z = math.sin(pose[2] / 2)
    stamped.pose.orientation.w = math.cos(pose[2] / 2)
    return stamped


def path_request(start: Pose2D, goal: Pose2D) -> ComputePathToPose.Goal:
    """A planner request from `start` (not from where the robot stands) to `goal`."""
    return ComputePathToPose.Goal(goal=map_pose(goal), start=map_pose(start), use_start=True)


def path_poses(path: Any) -> tuple[Pose2D, ...]:
    """A nav_msgs/Path as the port's poses: each with its orientation's heading, or, where a planner
    left it unset (the identity quaternion) before the goal, the bearing to the next pose."""
    points = [(float(p.pose.position.x), float(p.pose.position.y)) for p in path.poses]
    poses = []
    for index, stamped in enumerate(path.poses):
        q = stamped.pose.orientation
        unset = q.w == 1.0 and q.x == q.y == q.z == 0.0
        if unset and index + 1 < len(points):
            (x, y), (nx, ny) = points[index], points[index + 1]
            yaw = math.atan2(ny - y, nx - x)
        else:
            yaw = yaw_of(q)
        poses.append((*points[index], yaw))
    return tuple(poses)


def result_of(client: Any, goal: Any, timeout_s: float) -> Any | None:
    """Send `goal` and wait for its result (None: rejected, aborted or not within `timeout_s`)."""
    answered, outcome = threading.Event(), {}

    def on_result(future: Any) -> None:
        response = future.result()
        succeeded = response is not None and response.status == GoalStatus.STATUS_SUCCEEDED
        outcome["result"] = response.result if succeeded else None
        answered.set()

    def on_accepted(future: Any) -> None:
        handle = future.result()
        if handle is None or not handle.accepted:
            answered.set()
            return
        handle.get_result_async().add_done_callback(on_result)

    client.send_goal_async(goal).add_done_callback(on_accepted)
    answered.wait(timeout_s)
    return outcome.get("result")
