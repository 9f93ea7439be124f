"""The reach sweep: every base pose the floor allows, either arm, judged with the robot model alone."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from lab_description.world import DEFAULT_WORLD, World, world_from_raw
from tiago_description import robot_model as rm
from tiago_description.reach_map import reach_model
from tiago_sim.inspection.reach_sweep import (
    TOOL_HEIGHT_ERROR_M,
    approach_needed,
    sweep_nest,
    sweep_world,
    unserved,
)
from tiago_sim.layouts.acceptance import Verdict, check_lab, confirm, reason_kind

FIXTURES = Path(__file__).resolve().parent / "fixtures"
DEEPWELL = {"length": 0.12776, "width": 0.08548, "height": 0.0441, "mass": 0.45}


def _default_raw() -> dict:
    raw = yaml.safe_load(Path(DEFAULT_WORLD).read_text())
    raw["labware_types"]["sbs_deepwell_96"] = dict(DEEPWELL)
    return raw


def _world(raw: dict) -> World:
    return world_from_raw(raw, "test lab", check_robot=False)


def test_a_picks_open_finger_tips_clear_the_plate_by_the_tools_height_error() -> None:
    _kinematics, hotel, _seed = reach_model()
    pad_tips = hotel.grasp_height_m - rm.PAD_TIP
    for height in (0.01435, 0.0441, 0.09):
        assert approach_needed(height) + pad_tips - height == pytest.approx(TOOL_HEIGHT_ERROR_M)


def test_the_default_labs_nests_serve_both_plate_types_with_room_to_spare() -> None:
    reaches = sweep_world(_world(_default_raw()))
    assert [(r.station, r.nest) for r in reaches] == [
        ("station_a", 1), ("station_a", 2), ("station_b", 1), ("station_b", 2)
    ]  # fmt: skip
    for reach in reaches:
        assert reach.served == ("sbs_microplate_96", "sbs_deepwell_96"), reach.line()
        assert reach.headroom is not None and reach.headroom > 0.1, reach.line()
    assert not unserved(reaches, ["sbs_deepwell_96"])


def test_a_bench_above_the_arms_reach_serves_no_labware_from_any_pose() -> None:
    raw = _default_raw()
    raw["stations"][0]["table"]["size"][2] = 1.10
    reaches = sweep_world(_world(raw))
    high = [reach for reach in reaches if reach.station == "station_a"]
    assert [reach.served for reach in high] == [(), ()]
    assert all(reach.headroom is not None and reach.headroom < 0 for reach in high)
    assert unserved(reaches, ["sbs_microplate_96"]) == high


def test_a_nest_deep_in_a_bench_has_no_free_pose_within_the_arms_reach() -> None:
    """The base's footprint and the hotel tray keep the base out of the bench: a nest 0.7 m behind the
    front edge lies beyond the 0.8 m the arm reaches ahead from every pose the floor allows."""
    raw = _default_raw()
    raw["stations"][0]["table"]["size"][0] = 1.6  # the front edge 0.45 m nearer the robot
    reach = sweep_nest(_world(raw), 0, 1)
    assert reach.served == () and reach.arm is None, reach.line()
    assert "no pose of the base is free" in reach.line()


def test_a_deep_well_plate_out_of_reach_where_a_microplate_is_served_confirms_the_refusal() -> None:
    """A standing bench: the top-down grasp reaches its nests with a microplate's low approach but not
    over a deep-well plate; the loader, asking for the tallest type, refuses, and the sweep confirms."""
    raw = _default_raw()
    for station in raw["stations"]:
        station["table"]["size"][2] = 0.93
        for field in ("standoff", "work_standoff", "lateral"):
            station["poi"].pop(field)
        station["nests"].pop("approach_height")
    verdict = check_lab(1, copy.deepcopy(raw))
    assert not verdict.accepted and "a nest out of reach" in {reason_kind(p) for p in verdict.problems}
    sweep = confirm(verdict)
    assert sweep.confirmed and not sweep.any_type
    assert all(reach.served == ("sbs_microplate_96",) for reach in sweep.tallest)


def test_a_lab_refused_for_the_view_alone_is_not_confirmed() -> None:
    raw = yaml.safe_load((FIXTURES / "furniture_lab_130003.yaml").read_text())
    verdict = check_lab(130003, raw)
    assert {reason_kind(problem) for problem in verdict.problems} == {"a marker out of view"}
    sweep = confirm(verdict)
    assert not sweep.confirmed and not sweep.any_type


def test_a_lab_the_loader_accepts_is_served_everywhere_by_the_sweep() -> None:
    raw = yaml.safe_load((FIXTURES / "layout_207020.yaml").read_text())
    assert check_lab(207020, raw).accepted
    assert not confirm(Verdict(207020, raw, ())).tallest
