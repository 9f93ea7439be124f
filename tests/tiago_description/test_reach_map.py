"""The shipped map of how high the arm reaches a nest top-down belongs to the robot model in the tree
and agrees with IK on it: a stale or wrong map would let the loader refuse a servable lab, or wave
through one the arm cannot serve (the loader runs IK itself only near the map's limit)."""

from __future__ import annotations

import pytest

from tiago_description import reach_map


def test_the_shipped_map_was_computed_from_this_robot_model() -> None:
    assert reach_map.map_model() == reach_model_digest(), "run python -m tiago_description.reach_map --write"


def reach_model_digest() -> str:
    return reach_map.model_digest()


@pytest.mark.parametrize(("x", "y"), [(0.45, -0.20), (0.60, -0.05), (0.65, -0.40)])
def test_grid_points_agree_with_a_fresh_bisection_on_the_model(x: float, y: float) -> None:
    stored = reach_map.interpolated_ceiling(x, y)
    fresh = reach_map.highest_reached(lambda z: reach_map.reaches_nest(x, y, z))
    assert stored is not None and fresh is not None
    assert abs(stored - fresh) <= 2 * reach_map.HEIGHT_TOLERANCE
    assert reach_map.reaches_nest(x, y, stored - 0.01)
    assert not reach_map.reaches_nest(x, y, stored + 0.03)


def test_between_grid_points_the_map_interpolates_and_outside_it_knows_nothing() -> None:
    xs, ys = reach_map.GRID_X, reach_map.GRID_Y
    corners = [reach_map.interpolated_ceiling(x, y) for x in xs[4:6] for y in ys[8:10]]
    middle = reach_map.interpolated_ceiling((xs[4] + xs[5]) / 2, (ys[8] + ys[9]) / 2)
    assert None not in corners and middle == pytest.approx(sum(corners) / 4)  # type: ignore[arg-type]
    assert reach_map.interpolated_ceiling(xs[-1] + 0.01, ys[0]) is None
