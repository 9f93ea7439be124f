"""The loader refuses what the TIAGo++ cannot serve, before anything moves: one test per reason,
each an edit of the default lab that breaks exactly one thing, and the message names the file, the
station and the numbers. The shipped worlds all pass (they are served in the deployment tests)."""

from __future__ import annotations

import copy
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from lab_description.serviceability import (
    ALIGN_DRIVE_OVERSHOOT,
    ALIGN_SIGHTING_ERROR,
    MARKER_MAX_OBLIQUITY_DEG,
    WORKING_CLEARANCE,
    bench_distance,
)
from lab_description.world import WorldError, load_world
from lab_description.world_schema import SCHEMA_FILE
from tiago_description.hotel_model import hotel_sweep_radius

DEFAULT = yaml.safe_load((SCHEMA_FILE.parent / "default.yaml").read_text())


def refusal(tmp_path: Path, change: Callable[[dict[str, Any]], Any]) -> list[str]:
    data = copy.deepcopy(DEFAULT)
    change(data)
    path = tmp_path / "lab.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(WorldError) as refused:
        load_world(path)
    assert all(line.startswith(f"{path}: ") for line in refused.value.problems)
    return list(refused.value.problems)


def accepted(tmp_path: Path, change: Callable[[dict[str, Any]], Any]) -> None:
    """The default lab with `change` made loads."""
    data = copy.deepcopy(DEFAULT)
    change(data)
    path = tmp_path / "lab.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    load_world(path)


@pytest.mark.parametrize("world", sorted(SCHEMA_FILE.parent.glob("*.yaml")), ids=lambda p: p.name)
def test_every_shipped_world_passes_the_robot_checks(world: Path) -> None:
    load_world(world)


def test_a_nest_above_the_arms_reach_at_any_torso_height_is_refused(tmp_path: Path) -> None:
    def high_bench(data: dict[str, Any]) -> None:
        data["stations"][1]["table"]["size"][2] = 1.10

    problems = refusal(tmp_path, high_bench)
    reach = [line for line in problems if "reach" in line]
    assert reach and "stations[1]: 'station_b': nest 1 is out of the right arm's reach" in reach[0]
    assert "z 1.100 m" in reach[0]
    assert not any("stations[0]" in line for line in problems)


def test_a_working_pose_that_puts_the_base_inside_the_bench_is_refused(tmp_path: Path) -> None:
    def close(data: dict[str, Any]) -> None:
        data["stations"][0]["poi"]["work_standoff"] = 0.30

    problems = refusal(tmp_path, close)
    assert any(
        "stations[0]: 'station_a': the base at the working pose" in line
        and "from bench 'station_a'; the hotel tray's turning circle and the final approach's error "
        "needs 0.370 m"
        in line
        for line in problems
    ), problems


@pytest.mark.parametrize(("from_bench", "refused"), [(0.361, True), (0.371, False)])
def test_a_working_pose_within_the_tray_s_reach_plus_the_approach_error_is_refused(
    tmp_path: Path, from_bench: float, refused: bool
) -> None:
    """Random layout 92012: a working pose 0.361 m from its bench passed a check of 0.35 m (the tray
    reaches 0.354 m) and the tray touched the bench in the final approach, the base 12 mm nearer than
    its working pose. The clearance is the tray's corner from the hotel model plus the approach's error."""
    assert WORKING_CLEARANCE == pytest.approx(
        hotel_sweep_radius() + ALIGN_SIGHTING_ERROR + ALIGN_DRIVE_OVERSHOOT, abs=1e-12
    )
    assert hotel_sweep_radius() == pytest.approx(0.354, abs=0.0005)
    station = load_world(SCHEMA_FILE.parent / "default.yaml").station("station_a")
    working = station.aligned_pose()
    now = bench_distance(station, working.x, working.y)

    def nearer(data: dict[str, Any]) -> None:
        data["stations"][0]["poi"]["work_standoff"] = round(station.work_standoff - (now - from_bench), 4)

    if refused:
        problems = refusal(tmp_path, nearer)
        assert any(f"is {from_bench:.3f} m from bench 'station_a'" in line for line in problems), problems
    else:
        accepted(tmp_path, nearer)


def test_stations_too_close_for_the_hotel_tray_to_turn_are_refused(tmp_path: Path) -> None:
    def neighbour(data: dict[str, Any]) -> None:  # station_b's bench beside station_a's POI
        poi = load_world(SCHEMA_FILE.parent / "default.yaml").station("station_a").work_pose()
        data["stations"][1]["table"]["pose"] = [poi.x, poi.y + 0.80, 0.0]

    problems = refusal(tmp_path, neighbour)
    turning = [line for line in problems if "turning circle" in line and "stations[0]" in line]
    assert turning and "POI station_a_work" in turning[0] and "bench 'station_b'" in turning[0], problems
    assert "the navigation error needs 0.404 m" in turning[0]


def test_a_marker_the_head_camera_cannot_see_from_the_poi_is_refused(tmp_path: Path) -> None:
    def tilted_away(data: dict[str, Any]) -> None:  # a marker lying on the bench, face up, tilted 20 deg away
        data["stations"][0]["marker"]["rpy"] = [-20, 0, -90]
        data["stations"][0]["nests"]["site_in_marker_rpy"] = [20, 0, 0]  # the nests where they were
        data["stations"][0]["nests"]["site_in_marker_xyz"] = [-0.085, -0.0914, -0.129]

    problems = refusal(tmp_path, tilted_away)
    view = [line for line in problems if "cannot see marker 3 from POI station_a_work" in line]
    assert view and f"off its face's normal (at most {MARKER_MAX_OBLIQUITY_DEG:g})" in view[0], problems
    assert not any("reach" in line for line in problems)


@pytest.mark.parametrize(("bench_y", "refused"), [(-0.35, True), (-0.30, False)])
def test_a_bench_beside_the_undock_drive_is_refused(tmp_path: Path, bench_y: float, refused: bool) -> None:
    """Random layout 75051: the undock (straight ahead, no turn) passed a bench 0.265 m off its line
    and the base grazed it, though the docked pose and the dock's POI were both clear. Here the back of
    station_b's bench runs 0.30 m (refused) or 0.35 m (accepted) beside the line, its ends clear of both."""

    def beside(data: dict[str, Any]) -> None:
        data["dock"]["approach_distance"] = 1.6
        data["stations"][1]["table"]["pose"] = [-0.8, bench_y, -90.0]

    if refused:
        problems = refusal(tmp_path, beside)
        assert problems == [
            f"{tmp_path / 'lab.yaml'}: dock: the undock drive from the docked pose to POI dock_approach "
            "passes 0.300 m from bench 'station_b' (at x -1.260 y -1.000 m); the base's footprint and the "
            "navigation error need 0.315 m"
        ]
    else:
        accepted(tmp_path, beside)
