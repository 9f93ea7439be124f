"""The paths the robot would drive between the points of interest of a world, before it drives any.

Why: a world file can load and still leave a station the robot cannot reach (a cart across the
only corridor, two benches whose turning circles close the gap between them). The navigation stack
finds out only when a transfer drives there, minutes later; `world check` plans every pair of POIs
on the same inflated map the robot plans on and names each pair without a path. It also plans from
every pose the robot works at (a station's working pose, and the poses moved along the bench for a
long row's end nests) to the dock: a working pose moved next to a neighbouring bench could be driven
into but not left (random layouts 207020 and 207077: NAVIGATION_FAILED after the place). Pure; any thread.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

from lab_description.station_placement import working_poses
from lab_description.world import World
from tiago_sim.navigation.planner import GlobalPlanner, Plan, PlanningError, world_planner


@dataclass(frozen=True)
class PoiPath:
    """One pair of POIs: the plan between them, or why there is none."""

    start: str
    goal: str
    plan: Plan | None
    reason: str = ""


@dataclass(frozen=True)
class PoiPaths:
    """Every pair of POIs with its plan, and the planner whose maps they were planned on."""

    planner: GlobalPlanner
    paths: tuple[PoiPath, ...]
    stuck: tuple[str, ...] = ()
    """Per working pose with no plan to the dock: the station, the pose and why (`working_pose_exits`)."""

    def problems(self, source: str) -> list[str]:
        """One line per unreachable pair and per working pose the robot could not leave, in the words of
        the loader's problems (`file: field: ...`)."""
        unreachable = [
            f"{source}: pois: no path for the robot from {path.start} to {path.goal}: {path.reason}"
            for path in self.paths
            if path.plan is None
        ]
        return unreachable + [f"{source}: stations: {line}" for line in self.stuck]


def plan_poi_paths(world: World) -> PoiPaths:
    """Plan from each POI to every later one (in the world's order: the dock's first)."""
    planner = world_planner(world)
    paths = []
    for (start_name, start), (goal_name, goal) in combinations(world.pois.items(), 2):
        try:
            plan = planner.plan((start.x, start.y, start.yaw), (goal.x, goal.y, goal.yaw))
        except PlanningError as error:
            paths.append(PoiPath(start_name, goal_name, None, error.reason))
        else:
            paths.append(PoiPath(start_name, goal_name, plan))
    unplanned = [(path.start, path.goal) for path in paths if path.plan is None]
    cut_off = {name for pair in unplanned if world.dock_poi in pair for name in pair}
    return PoiPaths(planner, tuple(paths), tuple(working_pose_exits(world, planner, cut_off)))


def working_pose_exits(world: World, planner: GlobalPlanner, cut_off: set[str]) -> list[str]:
    """Each pose the robot works at (`serviceability.working_poses`) that no plan leaves for the dock,
    with the planner's reason and what would free it; not for the stations whose POIs are `cut_off`
    from the dock (named once, as a POI pair)."""
    dock = world.pois[world.dock_poi]
    stuck = []
    for station in world.stations:
        if station.poi in cut_off:
            continue
        for label, pose in working_poses(station):
            try:
                planner.plan((pose.x, pose.y, pose.yaw), (dock.x, dock.y, dock.yaw))
            except PlanningError as error:
                stuck.append(
                    f"{station.name}: the robot could not leave {label} ({pose.x:.2f}, {pose.y:.2f}) "
                    f"for the dock: {error.reason}; move what stands beside or behind that pose away, "
                    "or the nests nearer the row's middle"
                )
    return stuck
