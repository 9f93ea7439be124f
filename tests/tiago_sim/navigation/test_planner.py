"""The global planner on real occupancy grids (OpenCV inflation): around walls, no path, and start
and goal inside the inflated zone."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from lab_description.world import DEFAULT_WORLD, load_world
from lab_description.world_obstacles import KEEP_CLEAR_M
from tiago_description.robot_model import BASE_RADIUS
from tiago_sim.measuring.disturbances import DisturbanceLevels
from tiago_sim.navigation.occupancy_map import Footprint, OccupancyMap, build_map
from tiago_sim.navigation.plan_benchmark import measure
from tiago_sim.navigation.planner import (
    ARM_SWEEP_RADIUS_M,
    ARMS_CLEAR_ABOVE_M,
    FOOTPRINT_MARGIN_M,
    INFLATION_RADIUS_M,
    ROBOT_RADIUS_M,
    GlobalPlanner,
    PlanningError,
    hotel_sweep_radius,
    world_planner,
)

BENCH_IN_THE_WAY = DEFAULT_WORLD.parent / "bench_in_the_way.yaml"
UNUSUAL_BENCHES = DEFAULT_WORLD.parent / "unusual_benches.yaml"


def room(*footprints: Footprint, side: float = 6.0) -> OccupancyMap:
    """A walled square room of `side` m (5 cm cells) centred on the origin, with these outlines."""
    cells = round(side / 0.05)
    grid = np.zeros((cells, cells), dtype=bool)
    grid[:2, :] = grid[-2:, :] = grid[:, :2] = grid[:, -2:] = True
    return OccupancyMap(0.05, (-side / 2, -side / 2), grid).with_footprints(list(footprints))


def clearance_along(planner: GlobalPlanner, waypoints: tuple[tuple[float, float], ...]) -> float:
    """The least distance (m) from the path's points (every 1 cm) to an occupied cell."""
    clearance = planner.clearance
    least = math.inf
    for a, b in zip(waypoints, waypoints[1:], strict=False):
        for t in np.linspace(0.0, 1.0, max(2, int(math.dist(a, b) / 0.01))):
            row, col = planner.static_map.cell_of(a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t)
            least = min(least, float(clearance[row, col]))
    return least


def test_the_folded_arms_and_the_tray_set_the_inflation() -> None:
    # the tray plate's far corner: x 0.25 + (0.1318 + 0.03) / 2, y 0.07 + (0.0895 + 0.02) / 2
    assert hotel_sweep_radius() == pytest.approx(math.hypot(0.3309, 0.12475), abs=1e-3)
    assert ROBOT_RADIUS_M == ARM_SWEEP_RADIUS_M > hotel_sweep_radius()  # the arms reach farther
    assert INFLATION_RADIUS_M == pytest.approx(ROBOT_RADIUS_M + 0.05)


def test_a_path_goes_around_a_wall_with_the_turning_clearance() -> None:
    wall = Footprint(0.0, -0.5, 0.0, 0.2, 4.0)  # from the south wall to 1.5 m short of the north one
    planner = GlobalPlanner(room(wall))
    plan = planner.plan((-2.0, -1.0, 0.0), (2.0, -1.0, 0.0))
    assert plan.waypoints[0] == (-2.0, -1.0) and plan.waypoints[-1] == (2.0, -1.0)
    assert len(plan.waypoints) >= 3
    assert max(y for _, y in plan.waypoints) > 1.5 + INFLATION_RADIUS_M - 0.05  # over the wall's end
    assert clearance_along(planner, plan.waypoints) >= INFLATION_RADIUS_M - 0.05
    for x, y in plan.waypoints[1:-1]:  # every corner is a place where the robot may turn
        assert planner.inflated.is_free(x, y)
    assert plan.length_m < 4.0 + 2 * 2.6  # not a wander around the room


def test_a_closed_wall_leaves_no_path_and_says_so() -> None:
    planner = GlobalPlanner(room(Footprint(0.0, 0.0, 0.0, 0.2, 6.0)))
    with pytest.raises(PlanningError, match=r"no path from \(-2.00, 0.00\) to \(2.00, 0.00\)"):
        planner.plan((-2.0, 0.0, 0.0), (2.0, 0.0, 0.0))


def test_a_gap_narrower_than_the_turning_circle_is_no_path() -> None:
    gap = 2 * INFLATION_RADIUS_M - 0.1
    half = (6.0 - gap) / 2
    walls = [Footprint(0.0, -3.0 + half / 2, 0.0, 0.2, half), Footprint(0.0, 3.0 - half / 2, 0.0, 0.2, half)]
    with pytest.raises(PlanningError, match="no path"):
        GlobalPlanner(room(*walls)).plan((-2.0, 0.0, 0.0), (2.0, 0.0, 0.0))


def test_a_goal_inside_an_obstacle_is_refused_by_name() -> None:
    planner = GlobalPlanner(room(Footprint(1.0, 1.0, 0.0, 0.6, 0.6)))
    with pytest.raises(PlanningError, match=r"the goal \(1.00, 1.00\) is inside an obstacle"):
        planner.plan((-2.0, -2.0, 0.0), (1.0, 1.0, 0.0))


def test_a_start_facing_a_bench_inside_the_inflation_backs_out_straight() -> None:
    bench = Footprint(1.0, 0.0, 0.0, 0.7, 1.0)  # front edge at x 0.65
    planner = GlobalPlanner(room(bench))
    start = (0.65 - 0.32, 0.0, 0.0)  # 0.32 m from the bench: the tray (0.354 m) cannot turn here
    assert not planner.inflated.is_free(*start[:2])
    plan = planner.plan(start, (0.0, 2.0, math.pi / 2))
    assert plan.reverse_first
    exit_x, exit_y = plan.waypoints[1]
    assert exit_y == pytest.approx(0.0, abs=1e-6) and exit_x < start[0]  # straight back, along the heading
    assert planner.inflated.is_free(exit_x, exit_y)
    assert 0.65 - exit_x >= INFLATION_RADIUS_M - 0.05


def test_a_goal_inside_the_inflation_is_entered_along_its_heading() -> None:
    bench = Footprint(1.0, 0.0, 0.0, 0.7, 1.0)
    planner = GlobalPlanner(room(bench))
    goal = (0.65 - 0.32, 0.0, 0.0)  # facing the bench, 0.32 m from it
    plan = planner.plan((-2.0, 2.0, 0.0), goal)
    assert not plan.reverse_last  # arrives driving forwards, facing the bench
    entry = plan.waypoints[-2]
    assert entry[1] == pytest.approx(0.0, abs=1e-6) and entry[0] < goal[0]


def test_bench_in_the_way_is_planned_around_between_the_station_pois() -> None:
    world = load_world(BENCH_IN_THE_WAY)
    planner = GlobalPlanner(build_map(world))
    a, b = world.pois["station_a_work"], world.pois["station_b_work"]
    plan = planner.plan((a.x, a.y, a.yaw), (b.x, b.y, b.yaw))
    assert len(plan.waypoints) >= 3  # the straight line crosses bench_c
    (bench,) = world.obstacles
    for p, q in zip(plan.waypoints, plan.waypoints[1:], strict=False):
        for t in np.linspace(0.0, 1.0, 50):
            point = (p[0] + (q[0] - p[0]) * t, p[1] + (q[1] - p[1]) * t)
            assert bench.distance_to(*point) >= INFLATION_RADIUS_M - 0.05


def test_the_planning_benchmark_plans_on_the_12_m_map_and_reports_its_figures() -> None:
    """Behaviour only: the times themselves are the benchmark's to print (README, "The planner"),
    not a test's to assert on a machine whose load nobody controls."""
    result = measure(str(BENCH_IN_THE_WAY), plans=30, seed=3)
    assert result["cells"] == 240 * 240  # 12 x 12 m at 5 cm
    assert result["no_path"] == 0, "every free pose reaches every other in this lab"
    assert result["detours"] >= 1, "some pairs need the grid search, not a straight line"
    assert 0 < result["median_ms"] <= result["p90_ms"] <= result["max_ms"]
    assert result["detour_median_ms"] > 0


def test_a_straight_entry_past_a_tall_obstacle_within_the_arms_reach_is_refused() -> None:
    """Seed 98045: the goal could not be turned at, so it was entered along its heading, 1.25 m
    past a fridge 0.47 m beside the lane; the base had room, a folded arm grazed the fridge."""
    bench = Footprint(1.0, 0.0, 0.0, 0.7, 1.0)  # front edge at x 0.65; the goal faces it
    fridge = Footprint(-0.3, -0.47 - 0.3, 0.0, 1.0, 0.6)  # its near side 0.47 m right of the lane
    goal = (0.65 - 0.32, 0.0, 0.0)
    planner = GlobalPlanner(room(bench, fridge))
    with pytest.raises(PlanningError, match="folded arms"):
        planner.plan((-2.0, 2.0, 0.0), goal)
    low_cabinet = room(bench)  # the same box, but under the arms: only the bench reaches them
    plan = GlobalPlanner(room(bench, fridge), arms_map=low_cabinet).plan((-2.0, 2.0, 0.0), goal)
    assert plan.waypoints[-1] == goal[:2]


def test_the_arms_map_keeps_a_low_bench_but_not_its_tall_marker_board() -> None:
    world = load_world(UNUSUAL_BENCHES)
    (station,) = [s for s in world.stations if s.name == "low_bench"]  # a 0.60 m bench
    above = ARMS_CLEAR_ABOVE_M
    assert station.table_size[2] < above < station.top_height()  # a low bench with a tall board
    arms_map = build_map(world, above_m=above)
    static_map = build_map(world)
    bench_cells = static_map.occupied.sum() - arms_map.occupied.sum()
    assert bench_cells > 0
    marker = station.T_world_marker()[:2, 3]
    assert not arms_map.is_free(*marker)  # the board is on the arms' map
    assert arms_map.is_free(station.table_pose.x, station.table_pose.y)  # the low bench top is not


def test_the_obstacles_keep_clear_covers_the_planner_and_the_navigation_error() -> None:
    """A POI the robot stops up to 3 sigma off (per axis) is still one the planner accepts."""
    three_sigma = 3 * DisturbanceLevels().navigation_xy_m
    assert KEEP_CLEAR_M >= INFLATION_RADIUS_M + three_sigma


def test_a_start_inside_the_footprint_margin_leaves_backwards_and_never_nearer() -> None:
    """Random layout 131126 (campaign at 3798aea): the robot stood 0.362 m from the washer's bench,
    where it had worked (the loader keeps 0.370 m, less the final approach's error), and the 5 cm map
    put it 0.29 m away, inside the base's 0.295 m margin: no path out. The robot stands there; it
    leaves backwards, and no leg of the way goes nearer an obstacle than it stands."""
    world = load_world(Path(__file__).resolve().parent / "fixtures" / "layout_131126.yaml")
    planner = world_planner(world)
    start = (1.2008, 2.6039, 0.6863)  # where localisation put it after the pick
    row, col = planner.static_map.cell_of(*start[:2])
    assert planner.clearance[row, col] < BASE_RADIUS + FOOTPRINT_MARGIN_M  # inside the margin on the map
    reader = world.pois["reader_work"]
    plan = planner.plan(start, (reader.x, reader.y, reader.yaw))
    assert plan.reverse_first  # it backs away from the bench: it cannot turn there
    assert clearance_along(planner, plan.waypoints) >= planner.clearance[row, col] - 1e-6
    with pytest.raises(PlanningError, match=r"the goal \(1.20, 2.60\) is inside an obstacle or closer"):
        planner.plan((reader.x, reader.y, reader.yaw), start)  # as a goal it is still refused
