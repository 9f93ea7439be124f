"""The paths the robot would drive between the points of interest of a world, before it drives any.

Why: a world file can load and still leave a station the robot cannot reach (a cart across the
only corridor, two benches whose turning circles close the gap between them). The navigation stack
finds out only when a transfer drives there, minutes later; `world check` plans every pair of POIs
on the same inflated map the robot plans on and names each pair without a path. Pure; any thread.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

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

    def problems(self, source: str) -> list[str]:
        """One line per unreachable pair, in the words of the loader's problems (`file: field: ...`)."""
        return [
            f"{source}: pois: no path for the robot from {path.start} to {path.goal}: {path.reason}"
            for path in self.paths
            if path.plan is None
        ]


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
    return PoiPaths(planner, tuple(paths))
