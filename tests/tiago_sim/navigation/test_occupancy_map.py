"""The static map holds what the world file holds: walls, the dock, benches and obstacles."""

from __future__ import annotations

import math
from pathlib import Path

from lab_description.world import DEFAULT_WORLD, load_world
from tiago_sim.navigation.occupancy_map import build_map

BENCH_IN_THE_WAY = DEFAULT_WORLD.parent / "bench_in_the_way.yaml"


def test_obstacles_and_the_dock_are_on_the_map() -> None:
    world = load_world(BENCH_IN_THE_WAY)
    grid = build_map(world)
    (bench,) = world.obstacles
    assert not grid.is_free(bench.x, bench.y)
    corner_x, corner_y = bench.corners()[0]
    inward = (bench.x - corner_x, bench.y - corner_y)
    scale = 0.03 / math.hypot(*inward)
    assert not grid.is_free(corner_x + inward[0] * scale, corner_y + inward[1] * scale)
    dock = world.dock_pose
    assert not grid.is_free(dock.x - 0.32 * math.cos(dock.yaw), dock.y - 0.32 * math.sin(dock.yaw))
    assert grid.is_free(dock.x, dock.y)  # the docked robot itself is free space
    for pose in world.pois.values():
        assert grid.is_free(pose.x, pose.y)


def test_a_cylinder_is_a_disc_on_the_map(tmp_path: Path) -> None:
    pillar = "{name: pillar, shape: cylinder, pose: [3.0, -3.0, 0.0], radius: 0.25, height: 2.5}"
    text = DEFAULT_WORLD.read_text() + f"\nobstacles:\n  - {pillar}\n"
    path = tmp_path / "pillar.yaml"
    path.write_text(text)
    grid = build_map(load_world(path))
    assert not grid.is_free(3.0, -3.0) and not grid.is_free(3.0 + 0.22, -3.0)
    assert grid.is_free(3.0 + 0.33, -3.0) and grid.is_free(3.0 + 0.2, -3.0 + 0.2)
