"""`world check`: every shipped world loads, is summed up and drawn; the picture's robot sizes are
the robot model's."""

from __future__ import annotations

import io
import math
from pathlib import Path

import pytest

from tiago_sim.lab import world_picture
from tiago_sim.lab.world import load_world
from tiago_sim.lab.world_check import check_world, main
from tiago_sim.lab.world_schema import SCHEMA_FILE
from tiago_sim.robot import hotel_model, robot_model

WORLDS = sorted(SCHEMA_FILE.parent.glob("*.yaml"))
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("path", WORLDS, ids=[path.stem for path in WORLDS])
def test_every_shipped_world_is_checked_summed_up_and_drawn(tmp_path: Path, path: Path) -> None:
    world = load_world(path)
    out, err = io.StringIO(), io.StringIO()
    picture = tmp_path / f"{path.stem}.png"
    assert check_world(path, picture, out, err) == 0
    assert err.getvalue() == ""
    table = out.getvalue()
    for station in world.stations:
        row = next(line.split() for line in table.splitlines() if line.split()[:1] == [station.name])
        assert row[1:4] == [str(station.marker_id), str(station.sub_positions), station.poi]
    for name in world.labware_types:
        assert f"labware type {name}:" in table
    assert table.endswith(f"picture: {picture}\n")
    assert picture.read_bytes().startswith(PNG_SIGNATURE) and picture.stat().st_size > 20_000


def test_an_invalid_world_exits_1_with_one_line_per_problem(tmp_path: Path, capsys) -> None:
    path = tmp_path / "lab.yaml"
    path.write_text(SCHEMA_FILE.parent.joinpath("default.yaml").read_text() + "furniture: []\nstatoins: 1\n")
    picture = tmp_path / "lab.png"
    assert main([str(path), "--png", str(picture)]) == 1
    captured = capsys.readouterr()
    assert captured.out == "" and not picture.exists()
    assert captured.err.splitlines() == [
        f"{path}: furniture: unknown key; expected one of dock, floor_size, labware_types, name, "
        "obstacles, plates, pois, robot, stations",
        f"{path}: statoins: unknown key; did you mean 'stations'?",
    ]


def test_the_picture_draws_the_robot_the_robot_model_builds() -> None:
    assert world_picture.BASE_RADIUS_M == robot_model.BASE_RADIUS
    length, width = hotel_model.HOTEL_POCKET_SIZE
    farthest = max(math.hypot(x + length / 2, abs(y) + width / 2) for x, y, _ in hotel_model.HOTEL_SLOT_XYZ)
    # the pockets' corners and the posts and lead-ins around them (about 1 cm) stay inside the sweep
    assert farthest + 0.01 <= world_picture.HOTEL_SWEEP_RADIUS_M
