"""Obstacles in the world file: their fields are checked like every other, and where they stand too."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from lab_description.world import DEFAULT_WORLD, load_world
from lab_description.world_obstacles import Bench, bench_overlap_problems
from tests.lab_description.test_world_schema import Mutation, problems_of

BENCH_IN_THE_WAY = DEFAULT_WORLD.parent / "bench_in_the_way.yaml"


def add_obstacle(**obstacle: Any) -> Mutation:
    entry = {"name": "cart", "shape": "box", "pose": [0.0, -3.0, 0.0], "size": [0.6, 0.4], **obstacle}
    return lambda d: d.setdefault("obstacles", []).append({k: v for k, v in entry.items() if v is not None})


OBSTACLE_RULES: list[tuple[str, Mutation, str]] = [
    (
        "unknown shape",
        add_obstacle(shape="cone"),
        "obstacles[0].shape: expected 'box' or 'cylinder', got 'cone'",
    ),
    ("a box without size", add_obstacle(size=None), "obstacles[0].size: missing: a box needs size"),
    (
        "a cylinder with a size",
        add_obstacle(shape="cylinder", radius=0.2),
        "obstacles[0].size: a cylinder has no size; give radius only",
    ),
    (
        "a box size of 3 numbers",
        add_obstacle(size=[1, 2, 3]),
        "obstacles[0].size: expected a list of 2 numbers, got [1, 2, 3]",
    ),
    (
        "a negative size",
        add_obstacle(size=[0.5, -0.1]),
        "obstacles[0].size: all sizes must be positive, got [0.5, -0.1]",
    ),
    ("too tall", add_obstacle(height=5.0), "obstacles[0].height: 5.0 is outside -inf .. 3.0"),
    (
        "outside the floor",
        add_obstacle(pose=[5.9, -3.0, 0.0]),
        "obstacles[0].pose: 'cart' reaches outside the floor (5.60 .. 6.20, -3.20 .. -2.80 m; "
        "the floor is -6 .. 6 m)",
    ),
    (
        "on a bench",
        add_obstacle(pose=[2.3, 0.3, 30.0]),
        "obstacles[0].pose: 'cart' overlaps station_a's bench",
    ),
    (
        "on a POI",
        add_obstacle(shape="cylinder", size=None, radius=0.1, pose=[0.5, 1.3, 0.0]),
        "obstacles[0].pose: 'cart' is 0.20 m from POI 'lab_centre' at (0.50, 1.00); keep 0.62 m free there "
        "(the robot's sweep when it turns, the planner's margin and the navigation error)",
    ),
]


@pytest.mark.parametrize(
    ("rule", "mutate", "expected"), OBSTACLE_RULES, ids=[r for r, _, _ in OBSTACLE_RULES]
)
def test_each_obstacle_rule_names_the_field_and_the_numbers(
    tmp_path: Path, rule: str, mutate: Mutation, expected: str
) -> None:
    problems = problems_of(tmp_path, mutate)
    assert expected in problems, f"{rule}: {problems}"


def test_duplicate_obstacle_names_are_refused(tmp_path: Path) -> None:
    def two(d: dict[str, Any]) -> None:
        add_obstacle()(d)
        add_obstacle(pose=[-3.0, -3.0, 0.0])(d)

    assert problems_of(tmp_path, two) == ["obstacles[1].name: duplicate obstacle name 'cart'"]


def test_the_docking_path_is_kept_clear(tmp_path: Path) -> None:
    problems = problems_of(tmp_path, add_obstacle(pose=[-1.2, -1.5, 0.0], size=[0.3, 0.3]))
    assert any("the docking path (2/4)" in line for line in problems), problems


def test_bench_in_the_way_loads_its_obstacle_in_radians() -> None:
    world = load_world(BENCH_IN_THE_WAY)
    (bench,) = world.obstacles
    assert bench.name == "bench_c" and (bench.length, bench.width, bench.height) == (0.5, 0.9, 0.75)
    assert bench.yaw == pytest.approx(math.radians(142.0))
    assert not bench.is_cylinder


def test_overlapping_benches_are_refused(tmp_path: Path) -> None:
    """A bench standing in another (random layouts 91027 and 91033 drew such): the higher top covered
    the other's nest."""

    def overlap(d: dict[str, Any]) -> None:
        d["stations"][1]["table"]["pose"] = [2.3, 0.3, 30.0]

    assert problems_of(tmp_path, overlap) == [
        "stations[1].table.pose: station_b's bench overlaps station_a's bench"
    ]


def test_benches_side_by_side_are_accepted() -> None:
    benches = [Bench("a", 0.0, 0.0, 0.0, 0.6, 1.0), Bench("b", 0.6, 0.0, 0.0, 0.6, 1.0)]
    assert bench_overlap_problems(benches) == []
    benches.append(Bench("c", 0.3, 0.45, math.radians(90.0), 0.6, 0.4))
    assert bench_overlap_problems(benches) == [
        (2, "c's bench overlaps a's bench"),
        (2, "c's bench overlaps b's bench"),
    ]
