"""`world check`: every shipped world loads, is summed up, planned and drawn; a POI the robot cannot
reach is a problem; the picture's robot sizes are the robot model's."""

from __future__ import annotations

import io
import math
from pathlib import Path

import pytest
import yaml

from lab_description.world import load_world
from lab_description.world_schema import SCHEMA_FILE
from tiago_description import hotel_model, robot_model
from tiago_sim.inspection import world_picture
from tiago_sim.inspection.poi_paths import plan_poi_paths
from tiago_sim.inspection.world_check import check_world, main

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
    pairs = len(world.pois) * (len(world.pois) - 1) // 2
    assert f"paths: {pairs} of {pairs} POI pairs planned" in table
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
        "obstacles, plates, pois, robot, sensors, stations",
        f"{path}: statoins: unknown key; did you mean 'stations'?",
    ]


def test_the_picture_draws_the_robot_the_robot_model_builds() -> None:
    assert world_picture.BASE_RADIUS_M == robot_model.BASE_RADIUS
    length, width = hotel_model.HOTEL_POCKET_SIZE
    farthest = max(math.hypot(x + length / 2, abs(y) + width / 2) for x, y, _ in hotel_model.HOTEL_SLOT_XYZ)
    # the pockets' corners and the posts and lead-ins around them (about 1 cm) stay inside the sweep
    assert farthest + 0.01 <= world_picture.SWEEP_RADIUS_M


def _walled_off(tmp_path: Path) -> Path:
    """The default lab with a partition across the whole floor between the dock and station A: the
    file loads (the wall keeps 0.55 m clear of every POI), but station A is out of the robot's reach."""
    data = yaml.safe_load(SCHEMA_FILE.parent.joinpath("default.yaml").read_text())
    del data["pois"]  # lab_centre: too near the wall's line to keep clear of it
    data["obstacles"] = [
        {"name": "partition", "shape": "box", "pose": [0.3, 0.0, 0.0], "size": [0.2, 11.9], "height": 2.0}
    ]
    path = tmp_path / "walled.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_a_poi_the_robot_cannot_reach_fails_the_check_naming_both_pois(tmp_path: Path) -> None:
    path = _walled_off(tmp_path)
    world = load_world(path)  # the loader's own rules pass: only planning finds it
    out, err = io.StringIO(), io.StringIO()
    picture = tmp_path / "walled.png"
    assert check_world(path, picture, out, err) == 1
    problems = err.getvalue().splitlines()
    assert sorted(problems) == sorted(
        f"{path}: pois: no path for the robot from {start} to {goal}: {reason}"
        for start, goal, reason in _unreachable(world)
    )
    assert len(problems) == 2 and all("station_a_work" in line for line in problems)
    assert "1 of 3 POI pairs planned" in out.getvalue() and "2 without a path" in out.getvalue()
    assert picture.read_bytes().startswith(PNG_SIGNATURE)  # drawn: the red line shows where


def _unreachable(world) -> list[tuple[str, str, str]]:
    return [(p.start, p.goal, p.reason) for p in plan_poi_paths(world).paths if p.plan is None]


def test_planned_paths_keep_the_turning_circle_off_benches_and_obstacles() -> None:
    world = load_world(SCHEMA_FILE.parent / "furnished_lab.yaml")
    paths = plan_poi_paths(world)
    assert all(path.plan is not None for path in paths.paths)
    bent = [p for p in paths.paths if p.plan is not None and len(p.plan.waypoints) > 2]
    assert bent, "the furnished lab's obstacles bend at least one path"
    for path in paths.paths:
        assert path.plan is not None
        first, last = path.plan.waypoints[0], path.plan.waypoints[-1]
        start, goal = world.pois[path.start], world.pois[path.goal]
        assert math.dist(first, (start.x, start.y)) < 1e-6 and math.dist(last, (goal.x, goal.y)) < 1e-6


def test_a_refused_bench_is_swept_for_the_integrator_naming_the_labware_it_could_serve(
    tmp_path: Path,
) -> None:
    """The default lab's benches raised to 0.93 m, deep-well plates declared and no robot field: the
    loader refuses every nest for its approach over a deep-well plate; the sweep that follows on stdout
    says a microplate would be served, and from where. A refusal for the view alone is said to be the
    robot's choice of where to stand, not the reach."""
    raw = yaml.safe_load(SCHEMA_FILE.parent.joinpath("default.yaml").read_text())
    deepwell = {"length": 0.12776, "width": 0.08548, "height": 0.0441, "mass": 0.45}
    raw["labware_types"]["sbs_deepwell_96"] = deepwell
    for station in raw["stations"]:
        station["table"]["size"][2] = 0.93
        for field in ("standoff", "work_standoff", "lateral"):
            station["poi"].pop(field)
        station["nests"].pop("approach_height")
    path = tmp_path / "standing.yaml"
    path.write_text(yaml.safe_dump(raw))
    out, err = io.StringIO(), io.StringIO()
    assert check_world(path, None, out, err) == 1
    assert len(err.getvalue().splitlines()) == 4 and "out of the right arm's reach" in err.getvalue()
    swept = out.getvalue().splitlines()
    assert swept[0].startswith("reach sweep (top-down grasps")
    assert len(swept) == 5
    for line in swept[1:]:
        assert "(0.930 m): serves sbs_microplate_96, not sbs_deepwell_96; best from" in line
    view_only = Path(__file__).parents[1] / "layouts" / "fixtures" / "furniture_lab_130003.yaml"
    out = io.StringIO()
    assert check_world(view_only, None, out, io.StringIO()) == 1
    assert out.getvalue().splitlines()[1] == (
        "  centrifuge: every nest serves every labware type from some pose; the pose the robot chose "
        "to work from is what the refusal is about"
    )
