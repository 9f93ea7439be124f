"""Where the robot stands at a station follows from the bench, the nests and the robot model: a world
file without any robot field loads, the derived numbers keep the loader's own clearances, the file's
fields still override them, and a bench too high names what would make it servable."""

from __future__ import annotations

import copy
from typing import Any

import pytest
import yaml

from lab_description import station_placement as placement
from lab_description.serviceability import WORKING_CLEARANCE, bench_distance, top_down_ceiling
from lab_description.world import WorldError, world_from_raw
from lab_description.world_schema import SCHEMA_FILE
from tiago_description import robot_model as rm
from tiago_description import transforms as tf

DEFAULT = yaml.safe_load((SCHEMA_FILE.parent / "default.yaml").read_text())


def without_robot_fields(bench_height: float | None = None, **poi: float) -> dict[str, Any]:
    """The default lab with every robot field left out (then `poi` put back) and its benches' height."""
    data = copy.deepcopy(DEFAULT)
    for station in data["stations"]:
        station.pop("poi")
        station["nests"].pop("approach_height")
        if poi:
            station["poi"] = dict(poi)
        if bench_height is not None:
            station["table"]["size"][2] = bench_height
    return data


def test_a_lab_without_robot_fields_loads_with_places_derived_from_its_geometry() -> None:
    world = world_from_raw(without_robot_fields(), "lab")
    for station in world.stations:
        assert station.placement_from_file == frozenset()
        assert station.poi == f"{station.name}_work" and world.pois[station.poi] == station.work_pose()
        # the nearest working pose that keeps the bench the loader's clearance away
        working = station.aligned_pose()
        assert bench_distance(station, working.x, working.y) == pytest.approx(WORKING_CLEARANCE, abs=1e-3)
        assert bench_distance(station, working.x, working.y) >= WORKING_CLEARANCE
        assert station.standoff == pytest.approx(station.work_standoff + placement.FINAL_APPROACH_M)
        # the row's middle in the middle of the right arm's band
        T_base = tf.invert(working.matrix())
        ys = [(T_base @ station.T_world_site(n))[1, 3] for n in (1, station.sub_positions)]
        assert sum(ys) / 2 == pytest.approx(-rm.TOP_DOWN_REACH_BAND_M / 2, abs=1e-6)
        assert station.approach_height == placement.PREFERRED_APPROACH_HEIGHT_M


def test_the_file_s_fields_override_what_the_robot_derives() -> None:
    world = world_from_raw(without_robot_fields(work_standoff=0.55, lateral=0.10), "lab")
    station = world.stations[0]
    assert (station.work_standoff, station.lateral) == (0.55, 0.10)
    assert station.standoff == pytest.approx(0.55 + placement.FINAL_APPROACH_M)
    assert station.placement_from_file == {"work_standoff", "lateral"}
    only_standoff = world_from_raw(without_robot_fields(standoff=0.54), "lab").stations[0]
    assert only_standoff.work_standoff == only_standoff.standoff == 0.54  # the old files' meaning


def test_on_a_standing_bench_the_approach_comes_lower_but_clears_the_tallest_plate() -> None:
    world = world_from_raw(without_robot_fields(bench_height=0.90), "lab")
    tallest = max(t.height for t in world.labware_types.values())
    for station in world.stations:
        assert tallest + placement.APPROACH_CLEARANCE_M <= station.approach_height
        assert station.approach_height < placement.PREFERRED_APPROACH_HEIGHT_M


def test_a_nest_too_high_is_refused_naming_how_high_the_arm_reaches_and_what_would_help() -> None:
    with pytest.raises(WorldError) as refused:
        world_from_raw(without_robot_fields(bench_height=1.05), "lab")
    reach = [line for line in refused.value.problems if "out of the right arm's reach" in line]
    assert len(reach) == 4  # two nests on each of the two benches
    ceiling = top_down_ceiling(0.49, -0.14, 0.04)
    assert ceiling is not None and 0.85 < ceiling < 1.05
    assert "from here the arm reaches a nest up to" in reach[0]
    assert "lower the nest, or bring the row nearer the bench's front edge" in reach[0]


def test_a_long_row_is_worked_at_from_poses_moved_along_the_bench() -> None:
    """Six nests 0.15 m apart span 0.75 m: the end nests lie beyond the arm's band from the station's
    working pose, so each is worked at from a pose moved sideways, all at the same distance."""
    data = without_robot_fields()
    nests = data["stations"][1]["nests"]
    nests.update(sub_positions=6, spacing=0.15, site_in_marker_xyz=[-0.375, -0.09, 0.13])
    data["stations"][1]["table"]["size"][1] = 1.6
    station = world_from_raw(data, "lab").stations[1]
    working = station.aligned_pose().matrix()
    offsets = []
    for sub_position, T_world_base in placement.nest_working_poses(station):
        moved = tf.invert(working) @ T_world_base
        assert moved[0, 3] == pytest.approx(0.0, abs=1e-9)  # along the bench only
        inward = -(tf.invert(T_world_base) @ station.T_world_site(sub_position))[1, 3]
        assert placement.ARM_SIDE_MARGIN_M - 1e-9 <= inward
        assert inward <= rm.TOP_DOWN_REACH_BAND_M - placement.ARM_SIDE_MARGIN_M + 1e-9
        offsets.append(moved[1, 3])
    assert offsets[0] > 0 > offsets[-1] and offsets[2] == offsets[3] == 0.0


@pytest.mark.parametrize("tallest", [0.01435, 0.0441, 0.0641, 0.09])
def test_approach_heights_step_down_to_the_least_that_clears_a_neighbour_and_end_there(
    tallest: float,
) -> None:
    """Preferred first, in steps, then the least itself (a nest 0.96 m high near the base's centre
    line was reached 6 mm under the last step and not at it), never below the tallest plate plus the
    clearance, to the millimetre."""
    heights = placement.approach_heights(tallest)
    least = tallest + placement.APPROACH_CLEARANCE_M
    assert heights == sorted(heights, reverse=True) and len(set(heights)) == len(heights)
    assert all(height >= least - 1e-9 for height in heights)
    assert heights[-1] - least < 0.001, "the least height is tried last"
    assert heights[0] == max(placement.PREFERRED_APPROACH_HEIGHT_M, heights[-1])
