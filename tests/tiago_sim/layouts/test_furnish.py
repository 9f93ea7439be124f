"""Random obstacles for a given lab (`bench --random-obstacles`): every set loads with the robot
checks, keeps a path between every pair of POIs, stands off the places where the robot works and
turns, often stands in the way of a straight drive, and is the same for the same seed."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from lab_description.world import load_world, world_from_raw
from lab_description.world_obstacles import KEEP_CLEAR_M
from tiago_sim.inspection.poi_paths import plan_poi_paths
from tiago_sim.layouts.furnish import COUNT, furnish
from tiago_sim.layouts.layout_file import furnished_yaml

DEFAULT_WORLD = Path(__file__).resolve().parents[3] / "lab_description" / "worlds" / "default.yaml"
BASE = yaml.safe_load(DEFAULT_WORLD.read_text())
SEEDS = range(6000, 6012)


@pytest.fixture(scope="module")
def furnished() -> dict[int, dict]:
    return {seed: furnish(BASE, seed) for seed in SEEDS}


def test_every_set_loads_keeps_every_poi_reachable_and_stands_off_the_robots_places(furnished: dict) -> None:
    for seed, raw in furnished.items():
        world = world_from_raw(raw, f"seed {seed}")  # the robot checks included
        assert COUNT[0] <= len(world.obstacles) <= COUNT[1]
        assert not plan_poi_paths(world).problems("lab"), seed
        standing = [*world.pois.values(), *(station.work_pose() for station in world.stations)]
        for obstacle in world.obstacles:
            assert min(obstacle.distance_to(p.x, p.y) for p in standing) >= KEEP_CLEAR_M


def test_obstacles_stand_in_the_way_of_straight_drives(furnished: dict) -> None:
    """Most sets force the planner off a straight line somewhere: the campaign tests driving around."""

    def lengths(raw: dict) -> list[float]:
        return [
            path.plan.length_m for path in plan_poi_paths(world_from_raw(raw, "lab", check_robot=False)).paths
        ]

    empty = lengths(BASE)
    detours = sum(
        any(length > before + 0.05 for length, before in zip(lengths(raw), empty, strict=True))
        for raw in furnished.values()
    )
    assert detours >= len(SEEDS) // 2


def test_the_base_world_is_kept_and_the_same_seed_draws_the_same_set(furnished: dict, tmp_path: Path) -> None:
    raw = furnished[SEEDS[0]]
    assert raw["stations"] == BASE["stations"] and raw["plates"] == BASE["plates"]
    assert furnish(BASE, SEEDS[0]) == raw and furnish(BASE, SEEDS[1]) != raw
    path = tmp_path / "lab.yaml"
    path.write_text(furnished_yaml(DEFAULT_WORLD, SEEDS[0]))
    assert load_world(path).obstacles == world_from_raw(raw, "lab").obstacles
