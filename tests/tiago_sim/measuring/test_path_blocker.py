"""fault.block_path's values and where its box goes along a path (no physics)."""

from __future__ import annotations

import math

import pytest

from tiago_sim.measuring.path_blocker import CLOSED_AHEAD_M, BlockRequest, parse_block_path, point_along


def test_the_accepted_forms_of_the_value() -> None:
    assert parse_block_path("") is None
    assert parse_block_path("1.0") == BlockRequest(1.0, closed=False)
    assert parse_block_path("closed") == BlockRequest(CLOSED_AHEAD_M, closed=True)
    assert parse_block_path(" Closed:1.5 ") == BlockRequest(1.5, closed=True)


@pytest.mark.parametrize("value", ["sideways", "0.1", "7", "closed:far", "nan"])
def test_anything_else_is_refused_naming_the_value_and_the_forms(value: str) -> None:
    with pytest.raises(ValueError, match=rf"fault.block_path '{value}'.*'closed'"):
        parse_block_path(value)


def test_the_box_goes_along_the_path_past_its_corner_and_stops_at_its_end() -> None:
    path = ((0.0, 0.0), (1.0, 0.0), (1.0, 2.0))
    x, y, heading = point_along(path, (0.2, 0.05), 1.5)  # 0.8 m to the corner, 0.7 m up
    assert (x, y) == pytest.approx((1.0, 0.7))
    assert heading == pytest.approx(math.pi / 2)
    assert point_along(path, (0.0, 0.0), 10.0)[:2] == pytest.approx((1.0, 2.0))
