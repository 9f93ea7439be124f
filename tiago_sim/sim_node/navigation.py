"""Navigation in the sim node: the map on /map, the planned path on /plan, and drives along it.

Why here and not on the sim thread: planning is pure (navigation.planner) and takes milliseconds
to tens of them; run on the goal's executor thread it never stalls physics. The map is the one the
robot believes (the world file as the robot knows it, not the disturbed truth), published once and
latched (transient local), as map_server does; the planning map, inflated by the robot's turning
circle, goes out the same way on /global_costmap/costmap. Frames: ``map`` (the world frame; the
base pose estimate is in it). Lives on: rclpy executor threads (goals, one at a time).
"""

from __future__ import annotations

import logging
from typing import Any

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import PoseStamped
from labware_interfaces.msg import ErrorCodes
from nav_msgs.msg import OccupancyGrid, Path
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from tiago_sim.lab.world import World
from tiago_sim.navigation.occupancy_map import OccupancyMap, build_map
from tiago_sim.navigation.planner import GlobalPlanner, Plan, PlanningError
from tiago_sim.sim_node.action_run import ActionAbort, ActionRun
from tiago_sim.sim_node.publishers import stamp_of

log = logging.getLogger(__name__)

MAP_FRAME = "map"
OCCUPIED, FREE = 100, 0  # nav_msgs/OccupancyGrid: probability in percent; the map knows every cell


def grid_message(grid: OccupancyMap, stamp: Time) -> OccupancyGrid:
    """An OccupancyGrid in the map frame: row-major from the cell at ``grid.origin``, x fastest."""
    message = OccupancyGrid()
    message.header.frame_id = MAP_FRAME
    message.header.stamp = stamp
    message.info.map_load_time = stamp
    message.info.resolution = float(grid.resolution)
    rows, cols = grid.shape
    message.info.width, message.info.height = int(cols), int(rows)
    message.info.origin.position.x, message.info.origin.position.y = map(float, grid.origin)
    message.info.origin.orientation.w = 1.0
    message.data = np.where(grid.occupied, OCCUPIED, FREE).astype(np.int8).ravel().tolist()
    return message


def path_message(plan: Plan, goal_yaw: float, start_yaw: float, stamp: Time) -> Path:
    """The plan as nav_msgs/Path: each waypoint with the heading the robot has leaving it (the goal
    heading at the goal)."""
    message = Path()
    message.header.frame_id = MAP_FRAME
    message.header.stamp = stamp
    points = plan.waypoints
    for index, (x, y) in enumerate(points):
        if index + 1 < len(points):
            nx, ny = points[index + 1]
            yaw = float(np.arctan2(ny - y, nx - x))
        else:
            yaw = goal_yaw
        if index == 0 and plan.reverse_first:
            yaw = start_yaw
        pose = PoseStamped()
        pose.header = message.header
        pose.pose.position.x, pose.pose.position.y = float(x), float(y)
        pose.pose.orientation.z, pose.pose.orientation.w = float(np.sin(yaw / 2)), float(np.cos(yaw / 2))
        message.poses.append(pose)
    return message


class Navigation:
    """The planner on the believed map, its topics, and the navigate drive."""

    def __init__(self, node: Node, world: World) -> None:
        self.static_map = build_map(world)
        self.planner = GlobalPlanner(self.static_map)
        latched = QoSProfile(
            depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
        )
        self.map_pub = node.create_publisher(OccupancyGrid, "/map", latched)
        self.costmap_pub = node.create_publisher(OccupancyGrid, "/global_costmap/costmap", latched)
        self.plan_pub = node.create_publisher(Path, "/plan", latched)
        self.map_pub.publish(grid_message(self.static_map, stamp_of(0.0)))
        self.costmap_pub.publish(grid_message(self.planner.inflated, stamp_of(0.0)))
        self.last_plan: Plan | None = None

    def drive(
        self,
        run: ActionRun,
        goal: tuple[float, float, float],
        goal_name: str,
        *,
        span: tuple[float, float] = (0.0, 1.0),
        later_s: float = 0.0,
    ) -> Any:
        """Plan from the pose estimate to `goal`, publish the plan, follow it; NAVIGATION_FAILED
        (naming why) when no path exists."""
        start = run.sim(lambda sim: sim.pose_estimate())
        try:
            plan = self.planner.plan(start, goal)
        except PlanningError as error:
            raise ActionAbort(
                ErrorCodes.NAVIGATION_FAILED, f"no path to {goal_name}: {error.reason}"
            ) from None
        log.info(
            "plan to %s: %d waypoints, %.2f m, %.1f ms",
            goal_name,
            len(plan.waypoints),
            plan.length_m,
            plan.planning_s * 1000,
        )
        self.last_plan = plan
        self.plan_pub.publish(path_message(plan, goal[2], start[2], stamp_of(run.sim_thread.sim_time)))
        return run.run_motion(lambda sim: sim.follow_path(plan, goal[2]), span=span, later_s=later_s)
