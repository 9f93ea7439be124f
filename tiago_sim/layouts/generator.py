"""Random labs the TIAGo++ can serve, one per seed: the world files a campaign over unseen layouts runs.

Why: the robot was tuned on one lab; a lab integrator writes their own file. A layout drawn here
varies everything the world file lets them choose, within the schema's ranges and what the robot
can physically serve (`RANGES`, README "Random layouts"), and every layout passes the loader,
robot checks included (`lab_description.serviceability`). Same seed, same layout (Python's
`random.Random`, no global state); the result is the world file's mapping, ready for YAML.

Drawn per layout: 2 to 6 stations anywhere on the floor at any heading, the dock anywhere; per
station a sitting or standing bench's depth, width and height, 1 to 6 nests at a spacing and their
clearance, the marker's id and size on its stand beside the row (`station_draw.RANGES`). No robot
field: the robot derives where it stops and works (`lab_description.station_placement`). The plate to
move starts on any nest of the first station; other plates occupy other nests (the second station
keeps a free one, the transfer's destination) and sometimes hotel slot 2. Labware types: a 96-well
microplate and a 96-well deep-well plate, both SBS footprint.

Layout rules beyond the loader's: everything stays 0.3 m inside the floor's walls, and the straight
drives between the dock's POI and the stations' POIs keep the hotel tray's turning circle
(0.40 m) off every bench and the dock, since navigation drives straight from POI to POI today;
and the planner finds a way from and to where the robot may stop near each POI (the stop error),
the dock's included (`route_problems`). Pure; any thread.
"""

from __future__ import annotations

import dataclasses
import math
import random
from dataclasses import dataclass
from typing import Any

from lab_description import world_obstacles
from lab_description.floor_gaps import bench_distance, bench_distances, drive_points
from lab_description.serviceability import (
    HOTEL_SWEEP_RADIUS,
    TURN_MARGIN,
    WORKING_CLEARANCE,
    station_alone_problems,
)
from lab_description.station_placement import working_poses
from lab_description.world import Pose2D, Station, World, WorldError, station_from_raw, world_from_raw
from lab_description.world_schema import MARKER_DICTIONARY_SIZE, MIRROR_AMBIGUOUS_MARKER_IDS
from tiago_sim.inspection.poi_paths import plan_poi_paths
from tiago_sim.layouts.station_draw import LABWARE_TYPES, RANGES, draw_station
from tiago_sim.navigation.planner import PlanningError

STATION_NAMES = ("reader", "sealer", "incubator", "washer", "dispenser", "centrifuge", "labeler", "storage")
MARKER_IDS = tuple(i for i in range(MARKER_DICTIONARY_SIZE) if i not in MIRROR_AMBIGUOUS_MARKER_IDS)
WALL_MARGIN = 0.3  # m between anything the robot uses and the floor's edge (walls 0.1 m thick)
CORRIDOR = HOTEL_SWEEP_RADIUS + TURN_MARGIN
# A navigation goal is a POI moved by the stop error (tiago_sim.measuring.disturbances: 30 mm per axis
# and 2 deg, one sigma): with a POI 0.48 m from the next bench, a goal 36 mm off it was 0.45 m away
# and the planner found no straight way in along its heading. The drawing plans to and from goals
# two sigma off (and 1.5 sigma turned) too.
STOP_ERROR_M = 0.06
STOP_ERROR_RAD = math.radians(3.0)
TALLEST_LABWARE_M = max(sizes["height"] for sizes in LABWARE_TYPES.values())
PLACEMENT_TRIES = 300  # per station, before the whole floor is drawn again
LAYOUT_TRIES = 50


@dataclass(frozen=True)
class _Box:
    """An obstacle's outline as `bench_distance` reads a station's: pose of its centre, depth, width."""

    table_pose: Pose2D
    table_size: tuple[float, float, float]


def dock_box(world: World) -> _Box:
    """The dock's outline on the floor: a straight drive must keep off it as off a bench (a drive from
    the dock's POI back past the dock ran the robot into it)."""
    dock = world_obstacles.dock_box(world.dock_pose)
    return _Box(Pose2D(dock.x, dock.y, dock.yaw), (dock.length, dock.width, dock.height))


class LayoutError(RuntimeError):
    """The generator found no valid layout for a seed (its ranges would be too narrow)."""


def generate_layout(seed: int) -> dict[str, Any]:
    """The world file (a mapping) of the random lab with this seed; it passes `load_world`."""
    rng = random.Random(seed)
    problems: list[str] = []
    for _ in range(LAYOUT_TRIES):
        raw = _draw_layout(rng, seed)
        if raw is None:
            continue
        try:
            world = world_from_raw(raw, f"layout seed {seed}")
        except WorldError as error:  # a check the drawing does not foresee: draw again
            problems = list(error.problems)
            continue
        problems = route_problems(world)
        if problems:  # the straight corridors are clear, but no plan gets the robot round: draw again
            continue
        return raw
    raise LayoutError(f"no valid layout for seed {seed} in {LAYOUT_TRIES} tries; last: {problems[:3]}")


def route_problems(world: World) -> list[str]:
    """Why the robot could not drive this lab: two POIs with no planned path between them or a pose it
    works at that it could not leave for the dock (`world check`'s rules), or a stop near a POI
    (the dock's or a station's) it could not leave or reach. The drawing keeps
    straight drives 0.40 m from the benches (the tray's turning circle), the planner wants 0.53 m
    and the folded arms' band, so a drawn lab could have a dock that no plan leaves."""
    paths = plan_poi_paths(world)
    problems = paths.problems("layout")
    dock = world.pois[world.dock_poi]
    for station in world.stations:
        for stop in _stops_near(world.pois[station.poi]):
            for start, goal, what in ((dock, stop, "reaching"), (stop, dock, "leaving")):
                try:
                    paths.planner.plan((start.x, start.y, start.yaw), (goal.x, goal.y, goal.yaw))
                except PlanningError as error:
                    problems.append(f"layout: {what} {station.poi} {STOP_ERROR_M} m off: {error.reason}")
                    break
    # The undock ends near the dock's POI, not on it: a drawn dock 0.42 m from a bench let the robot
    # leave its POI but not a pose 1 cm beside it, where no turn was free.
    for stop in _stops_near(dock):
        for station in world.stations:
            goal = world.pois[station.poi]
            try:
                paths.planner.plan((stop.x, stop.y, stop.yaw), (goal.x, goal.y, goal.yaw))
            except PlanningError as error:
                problems.append(f"layout: leaving the dock {STOP_ERROR_M} m off its POI: {error.reason}")
                break
    return problems


def _stops_near(poi: Pose2D) -> list[Pose2D]:
    """Where navigation may stop for `poi` under its error: `STOP_ERROR_M` ahead, behind and to
    either side, turned by `STOP_ERROR_RAD` one way or the other."""
    c, s = math.cos(poi.yaw), math.sin(poi.yaw)
    offsets = (
        (STOP_ERROR_M, 0.0, 1),
        (-STOP_ERROR_M, 0.0, -1),
        (0.0, STOP_ERROR_M, -1),
        (0.0, -STOP_ERROR_M, 1),
    )
    return [
        Pose2D(poi.x + c * dx - s * dy, poi.y + s * dx + c * dy, poi.yaw + turn * STOP_ERROR_RAD)
        for dx, dy, turn in offsets
    ]


def layout_world(seed: int) -> World:
    """The generated lab as the program reads it."""
    return world_from_raw(generate_layout(seed), f"layout seed {seed}", f"layout_{seed}")


def draw_floor_plan(rng: random.Random, seed: int) -> dict[str, Any]:
    """The first floor plan drawn from `rng` that keeps the floor-plan rules (the loader's robot checks
    not yet run): what a lab integrator might have, before `world check`."""
    while (raw := _draw_layout(rng, seed, servable=False)) is None:
        pass
    return raw


def _draw_layout(rng: random.Random, seed: int, *, servable: bool = True) -> dict[str, Any] | None:
    """A floor plan, or None if a station found no place; `servable`: only stations the robot serves
    on their own (`_servable_station`), else any station the furniture ranges give."""
    count = rng.randint(*RANGES["stations"])
    floor = round(rng.uniform(*RANGES["floor_size"]) + 0.5 * count, 1)
    half = floor / 2 - WALL_MARGIN
    dock_pose = [
        round(rng.uniform(-half + 0.4, half - 0.4), 2),
        round(rng.uniform(-half + 0.4, half - 0.4), 2),
    ]
    dock_pose.append(float(rng.randrange(-180, 180)))
    dock = {"pose": dock_pose, "poi": "dock_approach", "approach_distance": round(rng.uniform(0.5, 0.8), 2)}
    names = rng.sample(STATION_NAMES, count)
    marker_ids = rng.sample(MARKER_IDS, count)
    stations: list[dict[str, Any]] = []
    raw = {
        "name": f"random layout {seed}",
        "floor_size": floor,
        "dock": dock,
        "robot": {"start": "docked", "hotel_slots": 2},
        "labware_types": {name: dict(sizes) for name, sizes in LABWARE_TYPES.items()},
        "stations": stations,
        "plates": [],
    }
    placed: World | None = None  # the lab of the stations placed so far
    for name, marker_id in zip(names, marker_ids, strict=True):
        station = _servable_station(rng, name, marker_id) if servable else draw_station(rng, name, marker_id)
        # where the robot works follows from the bench alone: placed once, moved with the table
        alone = station_from_raw(station, TALLEST_LABWARE_M)
        for _ in range(PLACEMENT_TRIES):
            pose = [round(rng.uniform(-half, half), 2), round(rng.uniform(-half, half), 2)]
            station["table"]["pose"] = [*pose, float(rng.randrange(-180, 180))]
            moved = None if alone is None else dataclasses.replace(alone, table_pose=_table_pose(station))
            if _may_fit(placed, moved, half) and (world := _fits(raw, station, half)) is not None:
                placed = world
                break
        else:
            return None
        stations.append(station)
    raw["plates"] = _plates(rng, stations)
    return raw


def _servable_station(rng: random.Random, name: str, marker_id: int) -> dict[str, Any]:
    """A drawn station the robot can serve on its own (`station_alone_problems`); the furniture ranges
    include benches above the arm's reach, which are drawn again."""
    while True:
        station = draw_station(rng, name, marker_id)
        placed = station_from_raw(station, TALLEST_LABWARE_M, reach=True)
        if placed is not None and not station_alone_problems(placed, advise=False):
            return station


def _may_fit(placed: World | None, new: Station | None, half: float) -> bool:
    """`_fits`'s own rules on the new station alone, before a new lab is built and checked: most
    candidates fail one of them (0.26 -> 0.1 s a layout)."""
    return True if new is None else _clear_alone(placed, new, half)  # None: the loader names it


def _table_pose(station: dict[str, Any]) -> Pose2D:
    x, y, yaw_deg = station["table"]["pose"]
    return Pose2D(x, y, math.radians(yaw_deg))


def _fits(raw: dict[str, Any], station: dict[str, Any], half: float) -> World | None:
    """The lab with the new station, if it passes the loader and `_clear_alone` against the stations
    placed before it; else None."""
    candidate = {**raw, "stations": [*raw["stations"], station]}
    try:
        world = world_from_raw(candidate, "layout", check_robot=False)
    except WorldError:
        return None
    placed = dataclasses.replace(world, stations=world.stations[:-1])
    return world if _clear_alone(placed, world.stations[-1], half) else None


def _clear_alone(placed: World | None, new: Station, half: float) -> bool:
    """The new station inside the floor, clear of the others and of every straight drive, checked
    only where it is involved: everything between the stations placed before it passed when they
    were placed. With `placed` None (no lab built yet) only what needs no dock."""
    if any(abs(c) > half for corner in _bench_corners(new) for c in corner):
        return False
    poi, workings = new.work_pose(), [pose for _label, pose in working_poses(new)]
    if placed is None:
        return not _outside(poi, half) and all(
            bench_distance(new, working.x, working.y) >= WORKING_CLEARANCE for working in workings
        )
    dock_poi = placed.pois[placed.dock_poi]
    if _outside(poi, half) or _outside(dock_poi, half):
        return False
    standing = [
        (placed.dock_pose, CORRIDOR),
        *((pose, WORKING_CLEARANCE) for s in placed.stations for _label, pose in working_poses(s)),
    ]
    if any(bench_distance(new, pose.x, pose.y) < clearance for pose, clearance in standing):
        return False
    if any(
        bench_distance(bench, working.x, working.y) < WORKING_CLEARANCE
        for bench in (*placed.stations, new)
        for working in workings
    ):
        return False
    points = [dock_poi, *(s.work_pose() for s in placed.stations)]
    obstacles = [*placed.stations, new, dock_box(placed)]
    drives = [(start, end) for i, start in enumerate(points) for end in points[i + 1 :]]
    if any(_segment_gap(start, end, new) < CORRIDOR for start, end in drives):
        return False
    return all(_segment_gap(start, poi, other) >= CORRIDOR for start in points for other in obstacles)


def _outside(point: Pose2D, half: float) -> bool:
    """A drive's end too near the floor's edge for the tray's turning circle."""
    return abs(point.x) > half - CORRIDOR or abs(point.y) > half - CORRIDOR


def _bench_corners(station) -> list[tuple[float, float]]:  # noqa: ANN001 - a lab.world.Station
    pose, (depth, width, _) = station.table_pose, station.table_size
    c, s = math.cos(pose.yaw), math.sin(pose.yaw)
    return [
        (pose.x + c * dx - s * dy, pose.y + s * dx + c * dy)
        for dx in (-depth / 2, depth / 2)
        for dy in (-width / 2, width / 2)
    ]


def _segment_gap(start, end, station, step: float = 0.05) -> float:  # noqa: ANN001
    """Least distance from the straight drive start -> end to the station's bench, sampled every
    `step` along the drive (negative: it enters the bench)."""
    count = max(1, math.ceil(math.hypot(end.x - start.x, end.y - start.y) / step))
    return float(bench_distances(station, *drive_points(start, end, count)).min())


def _plates(rng: random.Random, stations: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The plate to move on any nest of the first station; others on other nests (the second station
    keeps at least one free nest) and sometimes in hotel slot 2."""
    types = list(LABWARE_TYPES)
    source = stations[0]
    plates = [
        {
            "id": "plate_001",
            "type": rng.choice(types),
            "station": source["name"],
            "sub_position": rng.randint(1, source["nests"]["sub_positions"]),
        }
    ]
    taken = {(plates[0]["station"], plates[0]["sub_position"])}
    for index, station in enumerate(stations):
        nests = list(range(1, station["nests"]["sub_positions"] + 1))
        if index == 1:
            nests.remove(rng.choice(nests))  # the destination stays free
        for nest in nests:
            holder = (station["name"], nest)
            if holder in taken or rng.random() >= RANGES["occupied_nest_chance"]:
                continue
            taken.add(holder)
            plates.append(
                {
                    "id": f"plate_{len(plates) + 1:03d}",
                    "type": rng.choice(types),
                    "station": holder[0],
                    "sub_position": nest,
                }
            )
    if rng.random() < RANGES["hotel_plate_chance"]:
        plates.append({"id": f"plate_{len(plates) + 1:03d}", "type": rng.choice(types), "hotel_slot": 2})
    return plates
