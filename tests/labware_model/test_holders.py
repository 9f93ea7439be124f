"""Holders and locations of the labware model: one text form, strict values, nests that sort."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from labware_model.holders import (
    FLOOR,
    GRIPPER,
    UNKNOWN,
    Gripper,
    HotelSlot,
    Nest,
    aboard,
    location_text,
    parse_location,
)


@pytest.mark.parametrize(
    ("location", "text"),
    [
        (Nest("station_a", 1), "station:station_a:1"),
        (Nest("reader", 12), "station:reader:12"),
        (HotelSlot(2), "hotel:2"),
        (GRIPPER, "gripper"),
        (FLOOR, "floor"),
        (UNKNOWN, "unknown"),
    ],
)
def test_every_location_has_one_text_that_reads_back(location, text) -> None:
    assert location_text(location) == text
    assert parse_location(text) == location


@given(
    st.text(st.characters(exclude_categories=("Cs",)), min_size=1, max_size=30),
    st.integers(1, 10_000),
)
def test_any_nest_survives_the_text_round_trip(station: str, sub_position: int) -> None:
    nest = Nest(station, sub_position)  # a station name may contain ":" or "/"
    assert parse_location(location_text(nest)) == nest


@pytest.mark.parametrize(
    "text",
    ["", "station:", "station::1", "station:a", "station:a:0", "station:a:x", "station:a:01", "hotel:",
     "hotel:0", "hotel:-1", "hotel:01", "hotel:1.0", "shelf:1", "Gripper", "gripper ", "station_a/1"],
)  # fmt: skip
def test_text_that_is_no_location_is_refused_and_quoted(text: str) -> None:
    with pytest.raises(ValueError, match="not a location") as caught:
        parse_location(text)
    assert repr(text) in str(caught.value)


def test_location_text_refuses_what_is_not_a_location() -> None:
    with pytest.raises(TypeError, match="not a location"):
        location_text(("station_a", 1))  # type: ignore[arg-type]


def test_a_nest_reads_as_its_hand_over_position_and_compares_by_value() -> None:
    assert str(Nest("station_a", 1)) == "station_a/1"
    assert str(HotelSlot(2)) == "hotel slot 2"
    assert (str(GRIPPER), str(FLOOR), str(UNKNOWN)) == ("gripper", "floor", "unknown")
    assert Nest("rack", 2) == Nest("rack", 2) and Nest("rack", 2) != Nest("rack", 3)
    assert Nest("rack", 2) != HotelSlot(2)
    assert len({Nest("rack", 2), Nest("rack", 2), HotelSlot(2), HotelSlot(2)}) == 2
    assert Gripper() == GRIPPER and GRIPPER != FLOOR != UNKNOWN


def test_nests_sort_by_station_then_sub_position() -> None:
    nests = [Nest("b", 1), Nest("a", 10), Nest("a", 2)]
    assert sorted(nests) == [Nest("a", 2), Nest("a", 10), Nest("b", 1)]  # 2 before 10: numbers, not text
    assert sorted([HotelSlot(2), HotelSlot(1)]) == [HotelSlot(1), HotelSlot(2)]


@pytest.mark.parametrize(
    ("build", "problem"),
    [
        (lambda: Nest("rack", 0), "counts from 1, got 0"),
        (lambda: Nest("rack", -3), "counts from 1, got -3"),
        (lambda: Nest("rack", 1.0), "must be an integer"),
        (lambda: Nest("rack", True), "must be an integer"),
        (lambda: Nest("", 1), "needs a station name"),
        (lambda: Nest(None, 1), "needs a station name"),
        (lambda: HotelSlot(0), "counts from 1, got 0"),
        (lambda: HotelSlot("1"), "must be an integer"),
    ],
)
def test_bad_holder_values_are_refused_when_built(build, problem: str) -> None:
    with pytest.raises(ValueError, match=problem):
        build()


def test_holders_are_frozen() -> None:
    nest = Nest("rack", 1)
    with pytest.raises(AttributeError):
        nest.sub_position = 2  # type: ignore[misc]


def test_aboard_means_a_hotel_slot_or_the_gripper() -> None:
    assert aboard(HotelSlot(1)) and aboard(GRIPPER)
    assert not any(aboard(location) for location in (Nest("rack", 1), FLOOR, UNKNOWN))
