"""One random station in its table frame, and the ranges every random layout is drawn from.

Why these ranges: lab furniture as it is sold, which a lab integrator measures with a tape: sitting
benches 0.72 to 0.76 m high and standing benches 0.86 to 0.95 m, 0.6 to 0.9 m deep and 1.0 to 1.8 m
wide; 1 to 6 nests in a row 0.15 to 0.20 m apart, their centres 0.05 to 0.20 m behind the front
edge; the station's marker on a stand beside the row. Nothing about the robot is drawn: where it
stops, works and how high it approaches follow from these (`lab_description.station_placement`),
and the loader refuses what the TIAGo++ cannot serve (`lab_description.serviceability`).
Pure; any thread.
"""

from __future__ import annotations

import random
from typing import Any

RANGES: dict[str, Any] = {
    "stations": (2, 6),
    "floor_size": (8.0, 10.0),  # m, plus 0.5 m per station
    "sitting_bench_height": (0.72, 0.76),  # m, top surface = nest floor
    "standing_bench_height": (0.86, 0.95),  # m
    "standing_bench_chance": 0.5,
    "bench_depth": (0.60, 0.90),  # m
    "bench_width": (1.00, 1.80),  # m
    "nests": (1, 6),
    "spacing": (0.15, 0.20),  # m between nest centres; the row fits the bench's width
    "nest_from_front_edge": (0.05, 0.20),  # m, bench front edge to nest centre
    "marker_size": (0.10, 0.14),  # m
    "marker_beside_row": (0.02, 0.08),  # m between the end nest's brackets and the marker's board
    "marker_behind_nests": (-0.03, 0.05),  # m, the marker's face behind the nests' centre line
    "marker_above_top": (0.02, 0.08),  # m, the marker's lower edge above the bench top
    "clearance": (0.001, 0.002),  # m per side
    "occupied_nest_chance": 0.3,
    "hotel_plate_chance": 0.2,
}
LABWARE_TYPES: dict[str, dict[str, float]] = {
    "sbs_microplate_96": {"length": 0.12776, "width": 0.08548, "height": 0.01435, "mass": 0.35},
    "sbs_deepwell_96": {"length": 0.12776, "width": 0.08548, "height": 0.0441, "mass": 0.45},
}
NEST_HALF_EXTENT = 0.07  # m: half a plate's length plus the brackets' lead-in, along the row
MARKER_BOARD_SCALE = 1.4  # the board is this many times the marker's side (lab_description.world)
EDGE_MARGIN = 0.03  # m between a nest or the marker's board and the bench's side


def _between(rng: random.Random, key: str, digits: int = 3) -> float:
    low, high = RANGES[key]
    return round(rng.uniform(low, high), digits)


def draw_bench_height(rng: random.Random) -> float:
    """A sitting or a standing bench's top height (m)."""
    standing = rng.random() < RANGES["standing_bench_chance"]
    return _between(rng, "standing_bench_height" if standing else "sitting_bench_height")


def draw_station(rng: random.Random, name: str, marker_id: int) -> dict[str, Any]:
    """A station mapping as the world file holds it, with no robot field; the table pose is left for
    the floor plan. The marker stands beside one end of the row, facing the robot."""
    depth, width, height = _between(rng, "bench_depth"), _between(rng, "bench_width"), draw_bench_height(rng)
    size = round(rng.uniform(*RANGES["marker_size"]) / 0.005) * 0.005
    board = size * MARKER_BOARD_SCALE
    beside = _between(rng, "marker_beside_row")
    room = width - 2 * EDGE_MARGIN - 2 * NEST_HALF_EXTENT - beside - board  # for the row's length
    nests = rng.randint(*RANGES["nests"])
    while nests > 1 and room < (nests - 1) * RANGES["spacing"][0]:
        nests -= 1
    spacing = _between(rng, "spacing") if nests > 1 else 0.17
    if nests > 1:
        spacing = round(min(spacing, room / (nests - 1)), 3)
    row = (nests - 1) * spacing
    nest_edge = _between(rng, "nest_from_front_edge")
    marker_edge = round(nest_edge + rng.uniform(*RANGES["marker_behind_nests"]), 3)
    marker_z = round(size / 2 + rng.uniform(*RANGES["marker_above_top"]), 3)
    # the row and the marker side by side, somewhere along the bench (table y: marker x runs along -y)
    span = row + 2 * NEST_HALF_EXTENT + beside + board
    start = rng.uniform(-width / 2 + EDGE_MARGIN, width / 2 - EDGE_MARGIN - span)  # the group's low end
    marker_left = rng.random() < 0.5  # the marker on the robot's left of the row (table +y)
    if marker_left:
        marker_y = start + span - board / 2
        row_middle_y = start + NEST_HALF_EXTENT + row / 2
    else:
        marker_y = start + board / 2
        row_middle_y = start + board + beside + NEST_HALF_EXTENT + row / 2
    along = marker_y - row_middle_y  # the row's middle in the marker frame's x (table -y)
    return {
        "name": name,
        "table": {"pose": [0.0, 0.0, 0.0], "size": [depth, width, height]},
        "marker": {
            "id": marker_id,
            "size": size,
            "xyz": [round(-depth / 2 + marker_edge, 3), round(marker_y, 3), marker_z],
            "rpy": [90.0, 0.0, -90.0],
        },
        "nests": {
            "site_in_marker_xyz": [round(along - row / 2, 3), -marker_z, round(marker_edge - nest_edge, 3)],
            "site_in_marker_rpy": [-90.0, 0.0, 0.0],
            "sub_positions": nests,
            "spacing": spacing,
            "clearance": _between(rng, "clearance", 4),
        },
    }
