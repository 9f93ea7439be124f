"""A corpus of good and bad world files, judged twice: by the shipped JSON Schema (what an editor
checks as you type) and by the loader. Every good file passes both; every bad one fails both where
JSON Schema can state the rule. Rules across fields (unique names and ids, plates on nests and
types that exist, one plate per holder) are beyond JSON Schema: those files pass the schema and
only the loader refuses them, which the last test asserts so that the difference stays known."""

from __future__ import annotations

import copy
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import jsonschema
import pytest
import yaml

from lab_description.world import WorldError, load_world
from lab_description.world_schema import SCHEMA_FILE

WORLDS = sorted(SCHEMA_FILE.parent.glob("*.yaml"))
DEFAULT = yaml.safe_load((SCHEMA_FILE.parent / "default.yaml").read_text())
VALIDATOR = jsonschema.Draft202012Validator(json.loads(SCHEMA_FILE.read_text()))


def edited(change: Callable[[dict[str, Any]], Any]) -> dict[str, Any]:
    data = copy.deepcopy(DEFAULT)
    change(data)
    return data


def minimal() -> dict[str, Any]:
    """Only what has no default."""
    first = DEFAULT["stations"][0]
    return {
        "dock": {"pose": [0, 0, 0], "poi": "dock_approach"},
        "robot": {},
        "labware_types": {},
        "stations": [
            {
                "name": "only",
                "table": first["table"],
                "marker": {key: first["marker"][key] for key in ("id", "size", "xyz")},
                "nests": {
                    key: first["nests"][key] for key in ("site_in_marker_xyz", "sub_positions", "clearance")
                },
                "poi": {"name": "only_work", "standoff": 0.7},
            }
        ],
    }


GOOD = {
    **{path.name: yaml.safe_load(path.read_text()) for path in WORLDS},
    "minimal": minimal(),
    "plate in the hotel": edited(
        lambda d: d["plates"].append({"id": "p2", "type": "sbs_microplate_96", "hotel_slot": 1})
    ),
    "integers where numbers go": edited(lambda d: d.update(floor_size=10)),
}

BAD_FOR_BOTH = {
    "unknown top-level key": edited(lambda d: d.update(statoins=[])),
    "obstacles": edited(lambda d: d.update(obstacles=[[1.0, 2.0, 0.3]])),
    "unknown nested key": edited(lambda d: d["stations"][0]["nests"].update(spacng=0.1)),
    "unknown key in a labware type": edited(
        lambda d: d["labware_types"]["sbs_microplate_96"].update(colour="red")
    ),
    "missing key": edited(lambda d: d["stations"][0]["table"].pop("pose")),
    "text for a number": edited(lambda d: d.update(floor_size="big")),
    "true for a number": edited(lambda d: d["stations"][0]["marker"].update(size=True)),
    "float for an integer": edited(lambda d: d["stations"][0]["nests"].update(sub_positions=2.5)),
    "empty name": edited(lambda d: d["stations"][0].update(name="")),
    "short pose": edited(lambda d: d["dock"].update(pose=[1, 2])),
    "long pose": edited(lambda d: d["pois"].update(lab_centre=[1, 2, 3, 4])),
    "zero table width": edited(lambda d: d["stations"][0]["table"].update(size=[0.7, 0, 0.75])),
    "marker id out of the dictionary": edited(lambda d: d["stations"][0]["marker"].update(id=50)),
    "mirror-ambiguous marker id": edited(lambda d: d["stations"][0]["marker"].update(id=47)),
    "standoff out of range": edited(lambda d: d["stations"][0]["poi"].update(standoff=1.5)),
    "three hotel slots": edited(lambda d: d["robot"].update(hotel_slots=3)),
    "start elsewhere": edited(lambda d: d["robot"].update(start="charging")),
    "no stations": edited(lambda d: d.update(stations=[], plates=[])),
    "plate in a nest and a slot": edited(lambda d: d["plates"][0].update(hotel_slot=1)),
    "plate nowhere": edited(lambda d: d["plates"].append({"id": "p2", "type": "sbs_microplate_96"})),
    "plate with a station but no nest": edited(lambda d: d["plates"][0].pop("sub_position")),
}

BAD_FOR_THE_LOADER_ONLY = {
    "duplicate station name": edited(lambda d: d["stations"][1].update(name="station_a")),
    "duplicate marker id": edited(lambda d: d["stations"][1]["marker"].update(id=3)),
    "duplicate POI name": edited(lambda d: d["stations"][1]["poi"].update(name="dock_approach")),
    "unknown labware type": edited(lambda d: d["plates"][0].update(type="deep_well")),
    "unknown station": edited(lambda d: d["plates"][0].update(station="nowhere")),
    "nest past the row": edited(lambda d: d["plates"][0].update(sub_position=3)),
    "slot the robot does not use": edited(
        lambda d: (
            d["robot"].update(hotel_slots=1),
            d["plates"].append({"id": "p2", "type": "sbs_microplate_96", "hotel_slot": 2}),
        )
    ),
    "two plates in one nest": edited(lambda d: d["plates"].append({**d["plates"][0], "id": "p2"})),
    "duplicate plate id": edited(
        lambda d: d["plates"].append({"id": "plate_001", "type": "sbs_microplate_96", "hotel_slot": 1})
    ),
}


def loads(tmp_path: Path, data: dict[str, Any]) -> bool:
    path = tmp_path / "lab.yaml"
    path.write_text(yaml.safe_dump(data))
    try:
        load_world(path, check_robot=False)  # the file's rules; what the robot serves: test_serviceability
    except WorldError:
        return False
    return True


@pytest.mark.parametrize("name", list(GOOD))
def test_good_worlds_pass_the_schema_and_load(tmp_path: Path, name: str) -> None:
    errors = [error.message for error in VALIDATOR.iter_errors(GOOD[name])]
    assert errors == []
    assert loads(tmp_path, GOOD[name])


@pytest.mark.parametrize("name", list(BAD_FOR_BOTH))
def test_bad_worlds_fail_the_schema_and_the_loader(tmp_path: Path, name: str) -> None:
    assert not VALIDATOR.is_valid(BAD_FOR_BOTH[name])
    assert not loads(tmp_path, BAD_FOR_BOTH[name])


@pytest.mark.parametrize("name", list(BAD_FOR_THE_LOADER_ONLY))
def test_rules_across_fields_are_beyond_the_schema_and_the_loader_refuses_them(
    tmp_path: Path, name: str
) -> None:
    assert VALIDATOR.is_valid(BAD_FOR_THE_LOADER_ONLY[name])
    assert not loads(tmp_path, BAD_FOR_THE_LOADER_ONLY[name])
