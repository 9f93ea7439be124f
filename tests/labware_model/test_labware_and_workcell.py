"""Labware types, plates, readings and the workcell description of the labware model."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from labware_model.holders import Nest
from labware_model.labware import LabwareType, Plate
from labware_model.readings import NestReading, PlacementCheck
from labware_model.workcell import StationDescription, WorkcellDescription

SBS_96 = LabwareType("sbs_microplate_96", 0.12776, 0.08548, 0.01435, 0.35)


def test_a_labware_type_holds_its_sizes_in_metres_and_kilograms() -> None:
    assert (SBS_96.length, SBS_96.width, SBS_96.height, SBS_96.mass) == (0.12776, 0.08548, 0.01435, 0.35)


@pytest.mark.parametrize(
    ("changes", "problem"),
    [
        ({"name": ""}, "needs a name"),
        ({"length": 0.0}, "length must be positive, got 0.0"),
        ({"width": -0.08}, "width must be positive"),
        ({"height": math.nan}, "height must be a number"),
        ({"mass": "heavy"}, "mass must be a number"),
        ({"mass": True}, "mass must be a number"),
    ],
)
def test_a_labware_type_refuses_sizes_that_are_not_positive_numbers(changes: dict, problem: str) -> None:
    values = {"name": "plate", "length": 0.1, "width": 0.08, "height": 0.01, "mass": 0.3, **changes}
    with pytest.raises(ValueError, match=problem):
        LabwareType(**values)


def test_a_plate_needs_an_id_but_may_have_no_known_type() -> None:
    assert Plate("P1").labware_type == ""
    assert Plate("P1", "sbs_microplate_96") != Plate("P1", "")
    with pytest.raises(ValueError, match="needs a labware id"):
        Plate("", "sbs_microplate_96")


def test_readings_and_checks_are_plain_values() -> None:
    assert NestReading(Nest("rack", 1), True) == NestReading(Nest("rack", 1), True, "")
    check = PlacementCheck(True, True, 0.001, 0.0, Nest("rack", 1))
    assert check.outside == "" and check.location == Nest("rack", 1)


def test_the_workcell_finds_its_stations_by_name() -> None:
    rack = StationDescription("rack", 3, "rack_poi")
    workcell = WorkcellDescription((rack,), hotel_slots=2, pois=("rack_poi",), dock_poi="dock")
    assert workcell.station("rack") is rack and workcell.station("oven") is None


@pytest.mark.parametrize(
    ("name", "sub_positions", "problem"),
    [("", 1, "needs a name"), ("rack", 0, "at least one nest"), ("rack", 1.5, "must be an integer")],
)
def test_a_station_description_refuses_bad_values(name: str, sub_positions: object, problem: str) -> None:
    with pytest.raises(ValueError, match=problem):
        StationDescription(name, sub_positions, "poi")  # type: ignore[arg-type]


def test_the_model_imports_only_the_standard_library() -> None:
    """The bottom layer: importing it must pull in none of the project's other layers, nor numpy."""
    code = (
        "import sys, labware_model.holders, labware_model.labware, labware_model.readings, "
        "labware_model.workcell; "
        "print(sorted(m for m in sys.modules if m.split('.')[0] in "
        "{'numpy', 'rclpy', 'sila2', 'yaml', 'tiago_sim', 'ros_bridge', 'sila_labware'}))"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "[]"
