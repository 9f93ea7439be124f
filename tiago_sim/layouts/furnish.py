"""A given lab with 1 to 3 random free-standing obstacles, one set per seed: the world files of a
campaign that asks whether the robot drives around things it was not tuned for.

Why near the drives: obstacles dropped anywhere on a 12 m floor mostly stand where the robot never
goes. Each one is drawn near the straight line between two of the lab's points of interest (a
random point of it, up to `LATERAL_M` to either side), so many stand in the way and force a detour
or a narrower passage; the loader's placement rules keep them off the benches, inside the floor
and `KEEP_CLEAR_M` away from every place where the robot stands or turns ("off the stations"),
and a set is kept only if the planner still finds a path between every pair of POIs (as `world
check` demands). Same seed, same obstacles (`random.Random`). Pure; any thread.
"""

from __future__ import annotations

import copy
import math
import random
from typing import Any

from lab_description.world import World, WorldError, world_from_raw
from tiago_sim.inspection.poi_paths import plan_poi_paths
from tiago_sim.layouts.generator import LayoutError

COUNT = (1, 3)
LATERAL_M = 1.0
TRIES_PER_OBSTACLE = 60
SET_TRIES = 20
# (name, shape, size ranges): a box's [length, width] or a cylinder's radius (m), and its height (m)
KINDS: tuple[tuple[str, str, tuple[tuple[float, float], ...], float], ...] = (
    ("cart", "box", ((0.5, 0.8), (0.35, 0.55)), 0.9),
    ("pillar", "cylinder", ((0.10, 0.25),), 2.5),
    ("fridge", "box", ((0.6, 0.9), (0.6, 0.8)), 1.8),
    ("partition", "box", ((0.10, 0.20), (0.8, 2.0)), 2.0),
    ("bin", "cylinder", ((0.15, 0.25),), 0.7),
)


def furnish(base: dict[str, Any], seed: int, source: str = "furnished lab") -> dict[str, Any]:
    """`base` (a world file's mapping, obstacles it has kept) with 1 to 3 more obstacles drawn from
    `seed`; the result passes `load_world` and every POI pair has a path."""
    rng = random.Random(seed)
    world = world_from_raw(base, source, check_robot=False)
    pois = list(world.pois.values())
    for _ in range(SET_TRIES):
        raw = copy.deepcopy(base)
        raw.setdefault("obstacles", [])
        wanted = rng.randint(*COUNT)
        for index in range(wanted):
            kind = rng.choice(KINDS)
            obstacle = _place_one(rng, raw, pois, kind, f"{kind[0]}_{index + 1}", source)
            if obstacle is None:
                break
            raw["obstacles"].append(obstacle)
        else:
            furnished = _accepted(raw, source)
            if furnished is not None:
                raw["name"] = f"{base.get('name', 'lab')} with obstacles, seed {seed}"
                return raw
    raise LayoutError(f"no obstacle set with a path between every pair of POIs for seed {seed}")


def _place_one(
    rng: random.Random, raw: dict[str, Any], pois: list[Any], kind: tuple, name: str, source: str
) -> dict[str, Any] | None:
    """An obstacle of `kind` near a random drive between two POIs, where the loader accepts it."""
    _, shape, sizes, height = kind
    for _ in range(TRIES_PER_OBSTACLE):
        start, end = rng.sample(pois, 2)
        along, across = rng.uniform(0.2, 0.8), rng.uniform(-LATERAL_M, LATERAL_M)
        dx, dy = end.x - start.x, end.y - start.y
        length = max((dx * dx + dy * dy) ** 0.5, 1e-6)
        x = start.x + along * dx - across * dy / length
        y = start.y + along * dy + across * dx / length
        obstacle: dict[str, Any] = {
            "name": name,
            "shape": shape,
            "pose": [round(x, 2), round(y, 2), float(rng.randrange(-180, 180))],
            "height": height,
        }
        if shape == "box":
            obstacle["size"] = [round(rng.uniform(*sizes[0]), 2), round(rng.uniform(*sizes[1]), 2)]
        else:
            obstacle["radius"] = round(rng.uniform(*sizes[0]), 2)
        if any(_apart(obstacle, other) < 0.05 for other in raw["obstacles"]):
            continue  # two things do not stand in one place
        candidate = {**raw, "obstacles": [*raw["obstacles"], obstacle]}
        try:
            world_from_raw(candidate, source, check_robot=False)
        except WorldError:
            continue
        return obstacle
    return None


def _apart(first: dict[str, Any], second: dict[str, Any]) -> float:
    """A lower bound of the floor gap between two obstacles (their enclosing circles)."""

    def reach(obstacle: dict[str, Any]) -> float:
        if obstacle["shape"] == "cylinder":
            return float(obstacle["radius"])
        length, width = obstacle["size"]
        return math.hypot(length, width) / 2

    (x1, y1, _), (x2, y2, _) = first["pose"], second["pose"]
    return math.hypot(x2 - x1, y2 - y1) - reach(first) - reach(second)


def _accepted(raw: dict[str, Any], source: str) -> World | None:
    """The furnished world if the loader (robot checks included) takes it and every POI pair has a path."""
    try:
        world = world_from_raw(raw, source)
    except WorldError:
        return None
    return world if not plan_poi_paths(world).problems(source) else None
