"""`sila-labware serve/demo --world bad.yaml` and `sila-labware world check bad.yaml`: the message a
lab technician editing the world file needs - one line per problem naming the file, the field and
what is wrong, every problem at once - shown by the real CLI before anything starts (exit 2, bad
usage), in the words of `world check` (exit 1)."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from tests.helpers.sila_stack import DEFAULT_WORLD, free_port_base

CLI = [sys.executable, "-m", "sila_labware.cli"]


def bad_world(tmp_path: Path, mutate: Callable[[dict[str, Any]], None]) -> Path:
    world = yaml.safe_load(DEFAULT_WORLD.read_text())
    mutate(world)
    path = tmp_path / "bad_world.yaml"
    path.write_text(yaml.safe_dump(world))
    return path


def run_with_world(command: str, world: Path) -> subprocess.CompletedProcess:
    arguments = [command, "--world", str(world), "--no-discovery", "--port-base", str(free_port_base(4))]
    return subprocess.run(
        [*CLI, *arguments], capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL
    )


def only_line(stderr: str) -> str:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    return lines[0]


@pytest.mark.parametrize(
    ("mutate", "field", "problem"),
    [
        (lambda w: w["stations"][1]["marker"].update(id=17), "stations[1].marker.id", "mirrored"),
        (lambda w: w["stations"][0]["table"].pop("pose"), "stations[0].table.pose", "missing"),
        (lambda w: w["plates"][0].update(station="nowhere"), "plates[0].station", "unknown station"),
    ],
)
def test_serve_refuses_an_invalid_world_in_one_line(
    tmp_path: Path, mutate: Callable[[dict[str, Any]], None], field: str, problem: str
) -> None:
    world = bad_world(tmp_path, mutate)
    done = run_with_world("serve", world)
    assert done.returncode == 2
    line = only_line(done.stderr)
    assert line.startswith("sila-labware: error: invalid world file:"), line
    assert str(world) in line and field in line and problem in line, line
    assert "serving" not in done.stdout


def test_demo_and_world_check_list_every_problem_in_the_same_words(tmp_path: Path) -> None:
    def three_problems(w: dict[str, Any]) -> None:
        w["furniture"] = [[1.0, 2.0, 0.5]]  # not part of the schema: refused like any unknown key
        w["stations"][0]["nests"]["spacng"] = w["stations"][0]["nests"].pop("spacing")
        w["stations"][1]["marker"]["id"] = 3

    world = bad_world(tmp_path, three_problems)
    expected = [
        f"{world}: furniture: unknown key; expected one of dock, floor_size, labware_types, name, "
        "obstacles, plates, pois, robot, sensors, stations",
        f"{world}: stations[0].nests.spacng: unknown key; did you mean 'spacing'?",
        f"{world}: stations[1].marker.id: marker id 3 already used",
    ]
    checked = subprocess.run([*CLI, "world", "check", str(world)], capture_output=True, text=True, timeout=60)
    assert (checked.returncode, checked.stdout) == (1, "")
    assert checked.stderr.splitlines() == expected
    done = run_with_world("demo", world)
    assert (done.returncode, done.stdout) == (2, "")
    first, *rest = done.stderr.splitlines()
    assert [first.removeprefix("sila-labware: error: invalid world file: "), *rest] == expected


def test_demo_refuses_unparsable_yaml_in_one_line(tmp_path: Path) -> None:
    world = tmp_path / "broken.yaml"
    world.write_text("stations: [unclosed\n  - name: station_a\n")
    done = run_with_world("demo", world)
    assert done.returncode == 2
    line = only_line(done.stderr)
    assert str(world) in line and "not valid YAML" in line, line
    assert done.stdout == ""


def test_world_check_prints_the_table_and_draws_the_lab(tmp_path: Path) -> None:
    picture = tmp_path / "lab.png"
    done = subprocess.run(
        [*CLI, "world", "check", str(DEFAULT_WORLD), "--png", str(picture)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert (done.returncode, done.stderr) == (0, "")
    lines = done.stdout.splitlines()
    assert lines[0] == f"default lab: {DEFAULT_WORLD} (floor 12 m)"
    assert lines[2].split() == [
        "station_a",
        "3",
        "2",
        "station_a_work",
        "0.50",
        "m",
        "0.10",
        "m",
        "plate_001@1",
    ]
    assert lines[-1] == f"picture: {picture}" and picture.stat().st_size > 0


@pytest.mark.parametrize(
    ("arguments", "reason"),
    [
        (("world",), "the following arguments are required: {check}"),
        (("world", "check"), "the following arguments are required: file"),
    ],
)
def test_world_without_a_file_is_bad_usage(arguments: tuple[str, ...], reason: str) -> None:
    done = subprocess.run([*CLI, *arguments], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and reason in only_line(done.stderr)
