"""`python -m tiago_sim.inspection.world_check FILE [--png OUT]`: is a world file valid, and what is in it.

Why a command: a technician editing a lab file wants every problem at once before starting the
robot, and a look at the layout. Besides the loader's rules it plans a path between every pair of
POIs on the robot's own inflated map (tiago_sim.navigation): a POI the robot cannot reach is a
problem of the file too, found here rather than by a transfer minutes later.
`sila-labware world check` runs this module (and `serve`/`demo` run it before they start
anything): the SiLA side does not import the simulation's packages.

Exit codes: 0 valid, 1 invalid (every problem on stderr, one per line: `file: field: problem`),
2 bad usage.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO

from lab_description.world import World, WorldError, load_world
from labware_model.holders import HotelSlot, Nest
from tiago_sim.inspection.poi_paths import PoiPaths, plan_poi_paths
from tiago_sim.inspection.reach_sweep import SWEEP_TERMS, sweep_nest

INVALID_WORLD_EXIT_CODE = 1
_REACH_OR_VIEW = re.compile(
    r"'([^']+)': (?:nest \d+ is out of the \w+ arm's reach|the head camera cannot see)"
)


def _paths_line(paths: PoiPaths) -> str:
    planned = [path for path in paths.paths if path.plan is not None]
    line = f"paths: {len(planned)} of {len(paths.paths)} POI pairs planned"
    if planned:
        longest = max(planned, key=lambda path: path.plan.length_m)
        line += f", longest {longest.plan.length_m:.2f} m ({longest.start} -> {longest.goal})"
    missing = len(paths.paths) - len(planned)
    return line + (f"; {missing} without a path" if missing else "; every POI reachable from every other")


def _placed(field: str, station, value: str) -> str:  # noqa: ANN001 - a Station
    """A placement number, marked `*` where the robot chose it (the file left it out)."""
    return value if field in station.placement_from_file else f"{value}*"


def summary(world: World, paths: PoiPaths) -> str:
    """A short table: the stations with marker, nests, POI and plates; the other POIs; labware types;
    obstacles; the planned paths."""
    plates_at: dict[str, list[str]] = {}
    aboard = []
    for plate, holder in world.plates.items():
        if isinstance(holder, Nest):
            plates_at.setdefault(holder.station, []).append(f"{plate.labware_id}@{holder.sub_position}")
        elif isinstance(holder, HotelSlot):
            aboard.append(f"{plate.labware_id}@{holder.index}")
    rows = [("station", "marker", "nests", "POI", "works at", "approach", "plates")]
    for station in world.stations:
        plates = " ".join(plates_at.get(station.name, [])) or "-"
        rows.append(
            (
                station.name,
                str(station.marker_id),
                str(station.sub_positions),
                station.poi,
                _placed("work_standoff", station, f"{station.work_standoff:.2f} m"),
                _placed("approach_height", station, f"{station.approach_height:.2f} m"),
                plates,
            )
        )
    widths = [max(len(row[column]) for row in rows) for column in range(len(rows[0]))]
    lines = [f"{world.name}: {world.source} (floor {world.floor_size:g} m)"]
    lines += [
        "  " + "  ".join(cell.ljust(width) for cell, width in zip(row, widths, strict=True)).rstrip()
        for row in rows
    ]
    station_pois = {station.poi for station in world.stations}
    others = [name for name in world.pois if name not in station_pois]
    if any(
        station.placement_from_file != {"standoff", "work_standoff", "lateral", "approach_height"}
        for station in world.stations
    ):
        lines.append("  *: chosen by the robot from the lab's geometry (the file leaves it out)")
    lines.append(f"POIs: {', '.join(others)} (in front of the dock: {world.dock_poi}), and one per station")
    lines.append(f"hotel: {world.hotel_slots} slots; {' '.join(aboard) or 'empty'}")
    for name, labware in world.labware_types.items():
        size = f"{labware.length * 1000:.1f} x {labware.width * 1000:.1f} x {labware.height * 1000:.1f} mm"
        lines.append(f"labware type {name}: {size}, {labware.mass:g} kg")
    for obstacle in world.obstacles:
        outline = (
            f"cylinder r {obstacle.radius:g} m"
            if obstacle.is_cylinder
            else f"box {obstacle.length:g} x {obstacle.width:g} m"
        )
        where = f"({obstacle.x:g}, {obstacle.y:g})"
        lines.append(f"obstacle {obstacle.name}: {outline}, {obstacle.height:g} m tall, at {where}")
    lines.append(_paths_line(paths))
    return "\n".join(lines) + "\n"


def check_world(path: Path, png: Path | None, out: TextIO, err: TextIO) -> int:
    """Validate (and draw) a world file; the exit code."""
    try:
        world = load_world(path)
    except WorldError as error:
        err.write("".join(f"{line}\n" for line in error.problems))
        out.write(_swept(path, error.problems))
        return INVALID_WORLD_EXIT_CODE
    paths = plan_poi_paths(world)
    out.write(summary(world, paths))
    if png is not None:  # drawn even when a path is missing: the picture shows where
        from tiago_sim.inspection.world_picture import draw_world  # matplotlib: only when drawing

        draw_world(world, png, paths)
        out.write(f"picture: {png}\n")
    problems = paths.problems(str(path))
    err.write("".join(f"{line}\n" for line in problems))
    return INVALID_WORLD_EXIT_CODE if problems else 0


def _swept(path: Path, problems: Sequence[str]) -> str:
    """For a station refused for its reach or its marker's view: whether any base pose the floor
    allows would reach its nests (`reach_sweep`). It tells an integrator whether the arm cannot reach
    a nest at all (lower it, or bring it forward) or the robot's choice of where to stand refused it."""
    named = {match.group(1) for match in map(_REACH_OR_VIEW.search, problems) if match}
    if not named:
        return ""
    try:
        world = load_world(path, check_robot=False)
    except WorldError:  # the file's own rules fail too: nothing to sweep
        return ""
    lines = [f"reach sweep ({SWEEP_TERMS}):"]
    for index, station in enumerate(world.stations):
        if station.name not in named:
            continue
        reaches = [sweep_nest(world, index, nest) for nest in range(1, station.sub_positions + 1)]
        short = [reach for reach in reaches if reach.not_served]
        lines += [f"  {reach.line()}" for reach in short] or [
            f"  {station.name}: every nest serves every labware type from some pose; the pose the robot "
            "chose to work from is what the refusal is about"
        ]
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="sila-labware world check", description="Validate a world file; optionally draw it."
    )
    parser.add_argument("world", type=Path, help="the world YAML")
    parser.add_argument("--png", type=Path, default=None, metavar="OUT", help="write a top-down picture here")
    args = parser.parse_args(argv)
    return check_world(args.world, args.png, sys.stdout, sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
