"""A top-down picture of a world file: floor, benches, nests, markers, POIs, the robot where it stops.

Why: a world file is a list of poses in three frames; a mistake (a bench turned the wrong way, a
marker facing the wall, a POI whose turning circle reaches into a bench) is obvious in a picture
and easy to miss in the numbers. The picture draws at every POI the base footprint and the circle
the robot sweeps when it turns there, the free-standing obstacles, and the paths the global planner
finds between the POIs (those the robot drives, on the map it drives on), with a red dashed line
where there is none. Matplotlib's Agg canvas only (headless, no pyplot state).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from lab_description.world import Pose2D, Station, World
from labware_model.holders import Nest
from tiago_description import transforms as tf
from tiago_description.robot_model import BASE_RADIUS
from tiago_sim.inspection.poi_paths import PoiPaths
from tiago_sim.navigation.planner import ROBOT_RADIUS_M

BASE_RADIUS_M = BASE_RADIUS
SWEEP_RADIUS_M = ROBOT_RADIUS_M
"""The robot's farthest point from the base centre in the travel pose (the folded arms; the hotel
tray's corner is nearer): the circle it sweeps in a turn, as the planner inflates by."""
ARROW_M = 0.35
PLATE_COLOURS = ("tab:orange", "tab:purple", "tab:cyan", "tab:olive", "tab:pink")


def _box(T_world: np.ndarray, length: float, width: float) -> np.ndarray:
    """The floor-plan corners of a rectangle centred on a frame, `length` along its x."""
    corners = [(sx * length / 2, sy * width / 2, 0.0, 1.0) for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    return (T_world @ np.array(corners).T)[:2].T


def _heading(ax: Axes, pose: Pose2D, colour: str, length: float = ARROW_M) -> None:
    ax.annotate(
        "",
        xy=(pose.x + length * math.cos(pose.yaw), pose.y + length * math.sin(pose.yaw)),
        xytext=(pose.x, pose.y),
        arrowprops={"arrowstyle": "->", "color": colour, "lw": 1.5},
    )


def _robot_at(ax: Axes, pose: Pose2D, name: str, colour: str) -> None:
    ax.add_patch(Circle((pose.x, pose.y), BASE_RADIUS_M, facecolor=colour, alpha=0.25, edgecolor=colour))
    ax.add_patch(Circle((pose.x, pose.y), SWEEP_RADIUS_M, fill=False, edgecolor=colour, ls="--", lw=0.8))
    _heading(ax, pose, colour)
    ax.text(pose.x, pose.y - SWEEP_RADIUS_M - 0.05, name, ha="center", va="top", fontsize=7, color=colour)


def _station(ax: Axes, world: World, station: Station, nest_size: tuple[float, float]) -> None:
    depth, width, _ = station.table_size
    table = _box(station.table_pose.matrix(), depth, width)
    ax.add_patch(Polygon(table, closed=True, facecolor="burlywood", edgecolor="saddlebrown", alpha=0.8))
    behind = station.T_world_table() @ tf.make_transform((depth / 2 + 0.15, 0.0, 0.0))
    ax.text(*behind[:2, 3], station.name, ha="center", va="center", fontsize=8, weight="bold")
    for nest in station.nests():
        T_site = station.T_world_site(nest.sub_position)
        ax.add_patch(Polygon(_box(T_site, *nest_size), closed=True, fill=False, edgecolor="dimgray"))
        ax.text(*T_site[:2, 3], str(nest.sub_position), ha="center", va="center", fontsize=7)
    T_marker = station.T_world_marker()
    ends = _box(T_marker, station.marker_size, 0.0)[[0, 1]]  # along the marker's x, its width
    ax.plot(ends[:, 0], ends[:, 1], color="black", lw=3)
    facing = T_marker[:2, 2]  # the marker's z: out of its face
    facing_yaw = math.atan2(facing[1], facing[0])
    _heading(ax, Pose2D(T_marker[0, 3], T_marker[1, 3], facing_yaw), "black", 0.2)
    ax.text(T_marker[0, 3], T_marker[1, 3], f" id {station.marker_id}", fontsize=7, va="bottom")
    _robot_at(ax, world.pois[station.poi], station.poi, "tab:blue")
    aligned = station.aligned_pose()
    ax.add_patch(Circle((aligned.x, aligned.y), BASE_RADIUS_M, fill=False, edgecolor="tab:blue", ls=":"))


def _plates(ax: Axes, world: World) -> list[str]:
    """Draw the plates in nests; the lines naming those in the hotel."""
    colours = {name: PLATE_COLOURS[i % len(PLATE_COLOURS)] for i, name in enumerate(world.labware_types)}
    aboard = []
    for plate, holder in world.plates.items():
        labware = world.labware_types[plate.labware_type]
        if not isinstance(holder, Nest):
            aboard.append(f"{plate.labware_id} ({plate.labware_type}) in hotel slot {holder.index}")
            continue
        T_site = world.station(holder.station).T_world_site(holder.sub_position)
        corners = _box(T_site, labware.length, labware.width)
        ax.add_patch(Polygon(corners, closed=True, facecolor=colours[plate.labware_type], alpha=0.7))
        ax.text(*(T_site @ tf.make_transform((0, -labware.width, 0)))[:2, 3], plate.labware_id, fontsize=6)
    return aboard


def _obstacles(ax: Axes, world: World) -> None:
    """The free-standing obstacles: grey boxes and discs with their names."""
    style = {"facecolor": "slategray", "edgecolor": "black", "alpha": 0.7}
    for obstacle in world.obstacles:
        if obstacle.is_cylinder:
            ax.add_patch(Circle((obstacle.x, obstacle.y), obstacle.radius, **style))
        else:
            ax.add_patch(Polygon(obstacle.corners(), closed=True, **style))
        ax.text(obstacle.x, obstacle.y, obstacle.name, ha="center", va="center", fontsize=7, color="white")


def _extent(world: World, margin: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """What the picture shows: everything placed, with a margin, within the floor (a large floor
    would leave the lab a speck)."""
    points = [(pose.x, pose.y) for pose in (world.dock_pose, *world.pois.values())]
    for station in world.stations:
        points += _box(station.table_pose.matrix(), *station.table_size[:2]).tolist()
    for obstacle in world.obstacles:
        low_x, low_y, high_x, high_y = obstacle.extent()
        points += [(low_x, low_y), (high_x, high_y)]
    half = world.floor_size / 2 + 0.1
    low = np.maximum(np.min(points, axis=0) - margin, -half)
    high = np.minimum(np.max(points, axis=0) + margin, half)
    side = max(high - low)  # square, as the axes are
    centre = (low + high) / 2
    return centre - side / 2, centre + side / 2


def _paths(ax: Axes, world: World, paths: PoiPaths) -> None:
    """The planned paths between POIs (thin blue), a red dashed straight line where none exists."""
    for path in paths.paths:
        if path.plan is None:
            start, goal = world.pois[path.start], world.pois[path.goal]
            ax.plot([start.x, goal.x], [start.y, goal.y], color="red", ls="--", lw=1.5)
        else:
            xs, ys = zip(*path.plan.waypoints, strict=True)
            ax.plot(xs, ys, color="tab:blue", lw=0.8, alpha=0.6)


def draw_world(world: World, path: Path, paths: PoiPaths | None = None) -> None:
    """Write the world's floor plan as a PNG to `path`, with the planned paths if given."""
    figure = Figure(figsize=(9, 9), dpi=110)
    ax = figure.add_subplot()
    half = world.floor_size / 2
    ax.add_patch(Polygon([(-half, -half), (half, -half), (half, half), (-half, half)], fill=False, lw=2))
    first_type = next(iter(world.labware_types.values()), None)
    for station in world.stations:
        pocket = (0.13, 0.09) if first_type is None else (first_type.length, first_type.width)
        clearance = 2 * station.nest_clearance
        _station(ax, world, station, (pocket[0] + clearance, pocket[1] + clearance))
    _obstacles(ax, world)
    if paths is not None:
        _paths(ax, world, paths)
    station_pois = {station.poi for station in world.stations}
    for name, pose in world.pois.items():
        if name not in station_pois:
            _robot_at(ax, pose, name, "tab:green")
    _robot_at(ax, world.dock_pose, "docked", "darkgreen")
    aboard = _plates(ax, world)
    types = ", ".join(world.labware_types) or "none"
    notes = [f"labware types: {types}", *(aboard or ["hotel: empty"])]
    ax.text(0.01, 0.99, "\n".join(notes), transform=ax.transAxes, fontsize=8, va="top", bbox={"fc": "white"})
    ax.set_title(
        f"{world.name} ({Path(world.source).name}), floor {world.floor_size:g} m\n"
        "base footprint (filled) and turning sweep (dashed) at each POI; dotted: working pose;\n"
        "thin blue: planned paths between POIs (red dashed: no path)",
        fontsize=9,
    )
    low, high = _extent(world)
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    ax.set_xlabel("world x (m)")
    ax.set_ylabel("world y (m)")
    ax.grid(True, lw=0.3)
    figure.savefig(path)
