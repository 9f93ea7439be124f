"""A picture of the map, its inflation and a planned path between two POIs.

    python -m tiago_sim.navigation.plan_picture --world FILE --start POI --goal POI --png OUT

Why: the numbers of a plan (waypoints, clearances) say little; the map with the inflated zone and
the path over it shows at once whether the robot keeps its turning circle clear of every bench.
Matplotlib's Agg canvas only (headless). A command-line tool: prints the plan to stdout.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from lab_description.world import DEFAULT_WORLD, load_world
from tiago_sim.navigation.planner import (
    INFLATION_RADIUS_M,
    ROBOT_RADIUS_M,
    GlobalPlanner,
    Plan,
    world_planner,
)


def draw_plan(planner: GlobalPlanner, plan: Plan, title: str, path: Path) -> None:
    """The static map (black), the inflated zone (grey), the path and the turning circle at each
    waypoint."""
    grid = planner.static_map
    shade = np.where(grid.occupied, 0.0, np.where(planner.inflated.occupied, 0.75, 1.0))
    rows, cols = grid.shape
    extent = (
        grid.origin[0],
        grid.origin[0] + cols * grid.resolution,
        grid.origin[1],
        grid.origin[1] + rows * grid.resolution,
    )
    figure = Figure(figsize=(8, 8), dpi=100)
    ax = figure.add_subplot()
    ax.imshow(shade, cmap="gray", vmin=0.0, vmax=1.0, origin="lower", extent=extent, interpolation="nearest")
    xs, ys = zip(*plan.waypoints, strict=True)
    ax.plot(xs, ys, "-o", color="tab:blue", lw=2, ms=4)
    for x, y in plan.waypoints:
        ax.add_patch(Circle((x, y), ROBOT_RADIUS_M, fill=False, edgecolor="tab:orange", lw=0.8))
    low = np.min(plan.waypoints, axis=0) - 1.5
    high = np.max(plan.waypoints, axis=0) + 1.5
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    ax.set_title(
        f"{title}\nblack: map; grey: inflated by {INFLATION_RADIUS_M:.2f} m; orange: turning sweep "
        f"{ROBOT_RADIUS_M:.2f} m at each waypoint; {plan.length_m:.2f} m",
        fontsize=9,
    )
    ax.set_xlabel("map x (m)")
    ax.set_ylabel("map y (m)")
    figure.savefig(path)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tiago_sim.navigation.plan_picture")
    parser.add_argument("--world", default=str(DEFAULT_WORLD))
    parser.add_argument("--start", required=True, help="a POI name")
    parser.add_argument("--goal", required=True, help="a POI name")
    parser.add_argument("--png", type=Path, required=True)
    args = parser.parse_args(argv)
    world = load_world(args.world)
    planner = world_planner(world)
    start, goal = world.pois[args.start], world.pois[args.goal]
    plan = planner.plan((start.x, start.y, start.yaw), (goal.x, goal.y, goal.yaw))
    draw_plan(planner, plan, f"{world.name}: {args.start} -> {args.goal}", args.png)
    waypoints = ", ".join(f"({x:.2f}, {y:.2f})" for x, y in plan.waypoints)
    sys.stdout.write(f"{plan.length_m:.2f} m through {waypoints}; wrote {args.png}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
