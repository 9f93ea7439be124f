"""The navigation stand-in: the map on /map, the planned path on /plan, and drives along it.

Why on the simulator's side: on a TIAGo++ the navigation stack (Nav2) plans, localises and drives;
the robot's skills only send it goals through the hardware port. Why on a thread of its own and
not on the sim thread: planning is pure (navigation.planner) and takes milliseconds to tens of
them; off the sim thread it never stalls physics. The map is the one the
robot believes (the world file as the robot knows it, not the disturbed truth), published once and
latched (transient local), as map_server does; the planning map, inflated by the robot's turning
circle, goes out the same way on /global_costmap/costmap. Things not on the map: the drive is
watched by the base laser (physics.guarded_path); stopped short of an obstacle, the robot marks
what it saw on a local copy of the map (this goal only; /map stays the static map) and plans again
from its pose estimate; with no way round it waits and re-tries (a fresh scan forgets marks it
now sees through) for BLOCKED_TIMEOUT_S of simulated time. Frames: ``map`` (the world frame; the
base pose estimate is in it). Lives on: a thread per goal (one goal at a time).
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Any

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import PoseStamped
from labware_interfaces.msg import ErrorCodes
from nav_msgs.msg import OccupancyGrid, Path
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from lab_description.world import World
from tiago_sim.navigation.blockage import UnmappedObstacles, marks, still_there
from tiago_sim.navigation.occupancy_map import OccupancyMap
from tiago_sim.navigation.planner import GlobalPlanner, Plan, PlanningError, world_planner
from tiago_sim.physics.guarded_path import PATH_BLOCKED, scan_in_map
from tiago_sim.physics.path_following import plan_poses
from tiago_sim.sim_node.publishers import stamp_of
from tiago_sim.sim_node.sim_thread import SimThread

log = logging.getLogger(__name__)

MAP_FRAME = "map"
BLOCKED_TIMEOUT_S = 20.0
"""Simulated seconds the robot waits for a path while obstacles not on the map leave none (a
person or a trolley in a corridor usually moves on within that), then the goal fails."""
RETRY_PERIOD_S = 2.0
"""While blocked: a fresh scan and a new plan this often (simulated seconds)."""
_WAIT_POLL_S = 0.02
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


def path_message(poses: tuple[tuple[float, float, float], ...], stamp: Time) -> Path:
    """A plan's poses (`path_following.plan_poses`: each waypoint with the heading the robot drives
    on from it, the goal heading at the goal) as nav_msgs/Path in the map frame."""
    message = Path()
    message.header.frame_id = MAP_FRAME
    message.header.stamp = stamp
    for x, y, yaw in poses:
        pose = PoseStamped()
        pose.header = message.header
        pose.pose.position.x, pose.pose.position.y = float(x), float(y)
        pose.pose.orientation.z, pose.pose.orientation.w = float(np.sin(yaw / 2)), float(np.cos(yaw / 2))
        message.poses.append(pose)
    return message


class NavigationFailed(Exception):
    """A navigation goal ends with a code of labware_interfaces/msg/ErrorCodes and a reason."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{code}: {message}")
        self.code, self.message = code, message


class NavigationGoal:
    """One goal of the navigation stand-in, as the hardware port's Execution: it runs on a thread
    of its own, beside the robot's software, as a navigation stack runs its goals."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.progress = 0.0
        self.phase = "planning"
        self.remaining_s = 0.0
        self.success = False
        self.error_code = ""
        self.message = ""
        self.result: dict[str, Any] = {}
        self.done = False
        self._finished = threading.Event()
        self._cancel = threading.Event()

    @property
    def cancel_requested(self) -> bool:
        return self._cancel.is_set()

    def cancel(self) -> None:
        self._cancel.set()

    def wait(self, timeout_s: float) -> bool:
        self._finished.wait(timeout_s)
        return self.done

    def finish(self, success: bool, code: str = "", message: str = "") -> None:
        self.success, self.error_code = success, "" if success else code
        self.message = message or ("done" if success else code)
        if success:
            self.progress, self.remaining_s = 1.0, 0.0
        self.done = True
        self._finished.set()


class Navigation:
    """The planner on the believed map, its topics, and the drives along its plans."""

    def __init__(self, node: Node, world: World, sim_thread: SimThread) -> None:
        self.sim_thread = sim_thread
        self.planner = world_planner(world)
        self.static_map = self.planner.static_map
        latched = QoSProfile(
            depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
        )
        self.map_pub = node.create_publisher(OccupancyGrid, "/map", latched)
        self.costmap_pub = node.create_publisher(OccupancyGrid, "/global_costmap/costmap", latched)
        self.plan_pub = node.create_publisher(Path, "/plan", latched)
        self.map_pub.publish(grid_message(self.static_map, stamp_of(0.0)))
        self.costmap_pub.publish(grid_message(self.planner.inflated, stamp_of(0.0)))
        self.unmapped = UnmappedObstacles(self.static_map)
        self.last_plan: Plan | None = None

    def plan_path(
        self, start: tuple[float, float, float], goal: tuple[float, float, float]
    ) -> tuple[tuple[float, float, float], ...]:
        """The static map's plan from `start` to `goal`, as a navigation stack hands one out
        (`path_following.plan_poses`); empty when there is none."""
        try:
            plan = self.planner.plan(start, goal)
        except PlanningError as error:
            log.info("no plan from %s to %s: %s", start, goal, error.reason)
            return ()
        return plan_poses(plan, goal[2])

    def navigate(self, goal: tuple[float, float, float], goal_name: str) -> NavigationGoal:
        """Start a goal: plan from the pose estimate to `goal` and drive there (see `_drive`)."""
        state = NavigationGoal("navigate")
        threading.Thread(
            target=self._run, args=(state, goal, goal_name), name="navigation", daemon=True
        ).start()
        return state

    def _run(self, state: NavigationGoal, goal: tuple[float, float, float], goal_name: str) -> None:
        try:
            self._drive(state, goal, goal_name)
        except NavigationFailed as failure:
            state.finish(False, failure.code, failure.message)
        except Exception as error:  # noqa: BLE001 - every goal ends with a result
            log.exception("navigation to %s failed", goal_name)
            state.finish(False, ErrorCodes.INTERNAL, f"internal error: {error}")
        else:
            state.finish(True)

    def _drive(self, state: NavigationGoal, goal: tuple[float, float, float], goal_name: str) -> None:
        """Plan from the pose estimate to `goal`, publish the plan, follow it while the laser
        watches the corridor ahead; stopped short of an obstacle not on the map, mark it on a local
        copy of the map and plan again from where the robot stands. NAVIGATION_FAILED (naming why)
        when no path exists on the static map, or when obstacles not on the map leave none for
        BLOCKED_TIMEOUT_S of simulated time (re-tried every RETRY_PERIOD_S meanwhile)."""
        sim_thread = self.sim_thread
        seen = np.zeros((0, 2))  # obstacles not on the map, seen during this goal (map frame)
        blocked_since: float | None = None
        while True:
            start = sim_thread.run(lambda sim: sim.pose_estimate())
            try:
                plan = self._plan(start, goal, seen)
            except PlanningError as error:
                if not len(seen):
                    raise NavigationFailed(
                        ErrorCodes.NAVIGATION_FAILED, f"no path to {goal_name}: {error.reason}"
                    ) from None
                now = sim_thread.sim_time
                blocked_since = now if blocked_since is None else blocked_since
                what = f"an obstacle not on the map near {_near_text(seen, start)}"
                if now - blocked_since >= BLOCKED_TIMEOUT_S:
                    raise NavigationFailed(
                        ErrorCodes.NAVIGATION_FAILED,
                        f"no path to {goal_name}: blocked by {what} for {BLOCKED_TIMEOUT_S:.0f} s "
                        f"(simulated): {error.reason}",
                    ) from None
                left_s = BLOCKED_TIMEOUT_S - (now - blocked_since)
                phase = f"waiting: the path to {goal_name} is blocked by {what}; re-trying for {left_s:.0f} s"
                self._wait(state, phase, RETRY_PERIOD_S)
                scan = sim_thread.run(scan_in_map)  # forget what is gone, add what is new
                kept = still_there(seen, scan.points, scan.origin, scan.beam_rad)
                seen = np.vstack([kept, self.unmapped.near_robot(scan.points, scan.pose[:2])])
                continue
            blocked_since = None
            self.last_plan = plan
            self.plan_pub.publish(path_message(plan_poses(plan, goal[2]), stamp_of(sim_thread.sim_time)))
            motion = sim_thread.run(
                lambda sim, plan=plan: sim.follow_path(plan, goal[2], watch=self.unmapped)
            )
            self._follow(state, motion)
            if motion.success:
                return
            if motion.error_code != PATH_BLOCKED:
                raise NavigationFailed(motion.error_code or ErrorCodes.MOTION_FAILED, motion.message)
            log.info("%s; planning again around it", motion.message)
            seen = np.vstack([seen, motion.seen])

    def _follow(self, state: NavigationGoal, motion: Any) -> None:
        """Wait for a drive, passing its progress on and a cancel request down to it."""
        cancel_sent = False
        while not motion.done:
            if self.sim_thread.stopped:
                raise NavigationFailed(ErrorCodes.INTERNAL, "simulation stopped")
            if state.cancel_requested and not cancel_sent:
                self.sim_thread.call(lambda _sim: motion.cancel())
                cancel_sent = True
            state.progress, state.phase, state.remaining_s = motion.progress, motion.phase, motion.remaining_s
            motion.finished.wait(_WAIT_POLL_S)

    def _plan(
        self, start: tuple[float, float, float], goal: tuple[float, float, float], seen: np.ndarray
    ) -> Plan:
        """A plan on the static map, or on a local copy with the seen obstacles marked."""
        local = self.static_map.with_footprints(marks(seen)) if len(seen) else None
        if local is None:
            planner = self.planner
        else:  # what the laser saw has no known height: the arms must keep clear of it too
            planner = GlobalPlanner(local, self.planner.arms_map.with_footprints(marks(seen)))
        plan = planner.plan(start, goal)
        log.info(
            "plan: %d waypoints, %.2f m, %.1f ms%s: %s",
            len(plan.waypoints),
            plan.length_m,
            plan.planning_s * 1000,
            f" ({len(seen)} points not on the map marked)" if len(seen) else "",
            " -> ".join(f"({x:.2f}, {y:.2f})" for x, y in plan.waypoints),
        )
        return plan

    def _wait(self, state: NavigationGoal, phase: str, duration_s: float) -> None:
        """Stand for `duration_s` of simulated time, saying why; cancellable."""
        until = self.sim_thread.sim_time + duration_s
        while self.sim_thread.sim_time < until:
            if self.sim_thread.stopped:
                raise NavigationFailed(ErrorCodes.INTERNAL, "simulation stopped")
            if state.cancel_requested:
                raise NavigationFailed(ErrorCodes.CANCELED, "canceled on request")
            state.phase, state.remaining_s = phase, until - self.sim_thread.sim_time
            time.sleep(_WAIT_POLL_S)


def _near_text(points: np.ndarray, pose: tuple[float, float, float]) -> str:
    """Where the nearest seen point is, in words."""
    nearest = points[int(np.argmin(np.hypot(*(points - np.array(pose[:2])).T)))]
    return f"({nearest[0]:.2f}, {nearest[1]:.2f})"
