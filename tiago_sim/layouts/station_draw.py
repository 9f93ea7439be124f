"""One random station in its table frame, and the ranges every random layout is drawn from.

Why these ranges: each is the schema's range narrowed to what the TIAGo++ serves, measured with
the robot model (pinocchio IK, right arm top-down, torso free; `lab_description.serviceability`):
from a working pose 0.45 to 0.55 m in front of the nests, both the grasp and the approach 0.12 m
above it are reachable for nests 0.55 to 0.80 m above the floor and 0 to 0.45 m to the right of the
base (0.85 m: none; the approach would need the torso above its 0.35 m). So the nest row, at most
0.45 m long, lies within that band, and the bench top (the nest floor) is 0.60 to 0.78 m high.
Pure; any thread.
"""

from __future__ import annotations

import random
from typing import Any

from lab_description.serviceability import WORKING_CLEARANCE
from tiago_description import robot_model as rm

RANGES: dict[str, Any] = {
    "stations": (2, 6),
    "floor_size": (8.0, 10.0),  # m, plus 0.5 m per station
    "bench_height": (0.60, 0.78),  # m, top surface = nest floor
    "bench_depth": (0.50, 0.90),  # m
    "bench_width_beyond_row": (0.35, 0.90),  # m, bench width minus the nest row's length
    "nests": (1, 4),
    "spacing": (0.15, 0.20),  # m between nests; at most 0.45 m / (nests - 1): the right arm's band
    "reach_band": rm.TOP_DOWN_REACH_BAND_M,  # m, right of the base, where every nest must lie
    "marker_size": (0.10, 0.14),  # m
    "marker_from_front_edge": (0.20, 0.30),  # m, bench front edge to marker
    "marker_above_top": (0.02, 0.08),  # m, the marker's lower edge above the bench top
    "nest_from_front_edge": (0.10, 0.15),  # m, bench front edge to nest centre; >= 0.08 m before the marker
    # work_standoff: at least the nest's distance from the front edge + WORKING_EDGE
    "row_offset_from_marker": (-0.08, 0.08),  # m, the row's middle beside the marker, along it
    "clearance": (0.001, 0.002),  # m per side
    "approach_height": (0.10, 0.12),  # m
    "work_standoff": (0.45, 0.55),  # m
    "standoff_beyond_work": (0.20, 0.24),  # m
    "occupied_nest_chance": 0.3,
    "hotel_plate_chance": 0.2,
}
LABWARE_TYPES: dict[str, dict[str, float]] = {
    "sbs_microplate_96": {"length": 0.12776, "width": 0.08548, "height": 0.01435, "mass": 0.35},
    "sbs_deepwell_96": {"length": 0.12776, "width": 0.08548, "height": 0.0441, "mass": 0.45},
}
NEST_HALF_EXTENT = 0.07  # m: half a plate's length plus the brackets' lead-in, along the row
EDGE_MARGIN = 0.03  # m between a nest or the marker and the bench's side
WORKING_EDGE = WORKING_CLEARANCE  # m: the loader's, the tray's turning circle and the final approach's error


def _between(rng: random.Random, key: str, digits: int = 3) -> float:
    low, high = RANGES[key]
    return round(rng.uniform(low, high), digits)


def draw_station(rng: random.Random, name: str, marker_id: int) -> dict[str, Any]:
    """A station mapping as the world file holds it; the table pose is left for the floor plan."""
    nests = rng.randint(*RANGES["nests"])
    band = RANGES["reach_band"]
    spacing = round(rng.uniform(RANGES["spacing"][0], min(RANGES["spacing"][1], band / max(nests - 1, 1))), 3)
    row = (nests - 1) * spacing
    depth = _between(rng, "bench_depth")
    width = round(max(0.6, row + rng.uniform(*RANGES["bench_width_beyond_row"])), 3)
    height = _between(rng, "bench_height")
    size = round(rng.uniform(*RANGES["marker_size"]) / 0.005) * 0.005
    marker_edge = _between(rng, "marker_from_front_edge")
    marker_z = round(size / 2 + rng.uniform(*RANGES["marker_above_top"]), 3)
    low, high = RANGES["nest_from_front_edge"]
    nest_edge = round(rng.uniform(low, min(high, marker_edge - 0.08)), 3)
    offset = _between(rng, "row_offset_from_marker")
    # marker x runs along table -y: the row's middle lies at table y = marker_y - offset
    room = width / 2 - EDGE_MARGIN
    marker_low = max(-room + size / 2, -room + row / 2 + NEST_HALF_EXTENT + offset)
    marker_high = min(room - size / 2, room - row / 2 - NEST_HALF_EXTENT + offset)
    marker_y = round(rng.uniform(marker_low, marker_high), 3)
    # the bench's front edge at least WORKING_EDGE ahead of the base at the working pose
    work = round(
        rng.uniform(max(RANGES["work_standoff"][0], nest_edge + WORKING_EDGE), RANGES["work_standoff"][1]), 3
    )
    lateral_low, lateral_high = max(row / 2, 0.05), min(band - row / 2, 0.30)
    return {
        "name": name,
        "table": {"pose": [0.0, 0.0, 0.0], "size": [depth, width, height]},
        "marker": {
            "id": marker_id,
            "size": size,
            "xyz": [round(-depth / 2 + marker_edge, 3), marker_y, marker_z],
            "rpy": [90.0, 0.0, -90.0],
        },
        "nests": {
            "site_in_marker_xyz": [round(offset - row / 2, 3), -marker_z, round(marker_edge - nest_edge, 3)],
            "site_in_marker_rpy": [-90.0, 0.0, 0.0],
            "sub_positions": nests,
            "spacing": spacing if nests > 1 else 0.17,
            "clearance": _between(rng, "clearance", 4),
            "approach_height": _between(rng, "approach_height"),
        },
        "poi": {
            "name": f"{name}_work",
            "standoff": round(work + rng.uniform(*RANGES["standoff_beyond_work"]), 3),
            "work_standoff": work,
            "lateral": round(rng.uniform(lateral_low, lateral_high), 3),
        },
    }
