"""The world file's rules, one test each: unknown keys, types, ranges and the rules across fields,
each named with the file and the field; every problem of a file reported at once; the shipped JSON
Schema is what the definition generates."""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from lab_description import world_schema
from lab_description.world import DEFAULT_WORLD, WorldError, load_world

Mutation = Callable[[dict[str, Any]], None]


def default_data() -> dict[str, Any]:
    return copy.deepcopy(yaml.safe_load(DEFAULT_WORLD.read_text()))


def write(tmp_path: Path, data: Any) -> Path:
    path = tmp_path / "lab.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def problems_of(tmp_path: Path, mutate: Mutation) -> list[str]:
    data = default_data()
    mutate(data)
    path = write(tmp_path, data)
    with pytest.raises(WorldError) as caught:
        load_world(path)
    assert str(caught.value).splitlines() == list(caught.value.problems)
    prefix = f"{path}: "
    assert all(line.startswith(prefix) for line in caught.value.problems)
    return [line.removeprefix(prefix) for line in caught.value.problems]


def station(index: int, part: str) -> Callable[[dict[str, Any]], dict[str, Any]]:
    return lambda d: d["stations"][index][part]


def add_plate(**plate: Any) -> Mutation:
    return lambda d: d["plates"].append({"id": "plate_002", "type": "sbs_microplate_96", **plate})


RULES: list[tuple[str, Mutation, str]] = [
    # unknown keys, at any depth, with the closest known key
    (
        "unknown top-level key",
        lambda d: d.update(statoins=[]),
        "statoins: unknown key; did you mean 'stations'?",
    ),
    (
        "unknown nested key",
        lambda d: station(0, "nests")(d).update(spacng=0.2),
        "stations[0].nests.spacng: unknown key; did you mean 'spacing'?",
    ),
    (
        "unknown key in a labware type",
        lambda d: d["labware_types"]["sbs_microplate_96"].update(lenght=0.1),
        "labware_types.sbs_microplate_96.lenght: unknown key; did you mean 'length'?",
    ),
    (
        "unknown key in a plate",
        lambda d: d["plates"][0].update(sub_postion=1),
        "plates[0].sub_postion: unknown key; did you mean 'sub_position'?",
    ),
    (
        "a furniture list is no part of the schema",
        lambda d: d.update(furniture=[[1.0, 2.0, 0.3]]),
        "furniture: unknown key; expected one of dock, floor_size, labware_types, name, obstacles, plates, "
        "pois, robot, sensors, stations",
    ),
    # missing keys and types
    ("missing key", lambda d: station(0, "table")(d).pop("pose"), "stations[0].table.pose: missing"),
    ("missing section", lambda d: d.pop("dock"), "dock: missing"),
    ("a number", lambda d: d.update(floor_size="big"), "floor_size: expected a number, got 'big'"),
    (
        "a bool is no number",
        lambda d: station(0, "marker")(d).update(size=True),
        "stations[0].marker.size: expected a number, got True",
    ),
    (
        "not a number",
        lambda d: station(0, "poi")(d).update(standoff=math.nan),
        "stations[0].poi.standoff: expected a number, got nan",
    ),
    (
        "an integer",
        lambda d: station(0, "nests")(d).update(sub_positions="two"),
        "stations[0].nests.sub_positions: expected an integer, got 'two'",
    ),
    (
        "a float is no integer",
        lambda d: station(0, "nests")(d).update(sub_positions=2.0),
        "stations[0].nests.sub_positions: expected an integer, got 2.0",
    ),
    (
        "a string",
        lambda d: station(1, "poi")(d).update(name=""),
        "stations[1].poi.name: expected a non-empty string, got ''",
    ),
    ("a mapping", lambda d: d.update(robot=["docked"]), "robot: expected a mapping, got list"),
    ("a list", lambda d: d.update(plates={"id": "x"}), "plates: expected a list, got {'id': 'x'}"),
    ("a non-empty list", lambda d: d.update(stations=[], plates=[]), "stations: expected a non-empty list"),
    (
        "a pose of 3",
        lambda d: d["dock"].update(pose=[1, 2]),
        "dock.pose: expected a list of 3 numbers, got [1, 2]",
    ),
    (
        "a vector of numbers",
        lambda d: station(0, "marker")(d).update(rpy=[90, "0", -90]),
        "stations[0].marker.rpy: expected a list of 3 numbers, got [90, '0', -90]",
    ),
    (
        "a POI pose",
        lambda d: d["pois"].update(lab_centre="here"),
        "pois.lab_centre: expected a list of 3 numbers, got 'here'",
    ),
    (
        "positive table sizes",
        lambda d: station(0, "table")(d).update(size=[0.7, 0.0, 0.75]),
        "stations[0].table.size: all sizes must be positive, got [0.7, 0.0, 0.75]",
    ),
    (
        "the only start",
        lambda d: d["robot"].update(start="anywhere"),
        "robot.start: expected 'docked', got 'anywhere'",
    ),
    # ranges
    (
        "marker size",
        lambda d: station(0, "marker")(d).update(size=0.05),
        "stations[0].marker.size: 0.05 is outside 0.1 .. 0.5",
    ),
    (
        "marker id in the dictionary",
        lambda d: station(0, "marker")(d).update(id=50),
        "stations[0].marker.id: 50 is outside 0 .. 49",
    ),
    (
        "mirror-ambiguous marker id",
        lambda d: station(1, "marker")(d).update(id=17),
        "stations[1].marker.id: id 17 also decodes when mirrored; avoid 8, 9, 17, 47",
    ),
    (
        "sub-positions",
        lambda d: station(0, "nests")(d).update(sub_positions=21),
        "stations[0].nests.sub_positions: 21 is outside 1 .. 20",
    ),
    (
        "clearance",
        lambda d: station(0, "nests")(d).update(clearance=0.0),
        "stations[0].nests.clearance: 0.0 is outside 0.0005 .. 0.02",
    ),
    (
        "approach height",
        lambda d: station(0, "nests")(d).update(approach_height=0.5),
        "stations[0].nests.approach_height: 0.5 is outside 0.02 .. 0.4",
    ),
    (
        "standoff",
        lambda d: station(0, "poi")(d).update(standoff=1.3),
        "stations[0].poi.standoff: 1.3 is outside 0.3 .. 1.2",
    ),
    (
        "work standoff",
        lambda d: station(0, "poi")(d).update(work_standoff=0.2),
        "stations[0].poi.work_standoff: 0.2 is outside 0.3 .. 1.0",
    ),
    (
        "lateral",
        lambda d: station(0, "poi")(d).update(lateral=-0.6),
        "stations[0].poi.lateral: -0.6 is outside -0.5 .. 0.5",
    ),
    (
        "dock approach",
        lambda d: d["dock"].update(approach_distance=3),
        "dock.approach_distance: 3 is outside 0.3 .. 2.0",
    ),
    ("hotel slots", lambda d: d["robot"].update(hotel_slots=3), "robot.hotel_slots: 3 is outside 1 .. 2"),
    ("floor size", lambda d: d.update(floor_size=1), "floor_size: 1 is outside 2.0 .. 100.0"),
    (
        "plate mass",
        lambda d: d["labware_types"]["sbs_microplate_96"].update(mass=5),
        "labware_types.sbs_microplate_96.mass: 5 is outside 0.01 .. 3.0",
    ),
    # across fields
    (
        "unique station names",
        lambda d: d["stations"][1].update(name="station_a"),
        "stations[1].name: duplicate station name 'station_a'",
    ),
    (
        "unique marker ids",
        lambda d: station(1, "marker")(d).update(id=3),
        "stations[1].marker.id: marker id 3 already used",
    ),
    (
        "unique POI names: station and dock",
        lambda d: station(1, "poi")(d).update(name="dock_approach"),
        "stations[1].poi.name: POI name 'dock_approach' already used",
    ),
    (
        "unique POI names: extra POI and dock",
        lambda d: d["pois"].update(dock_approach=[0, 0, 0]),
        "pois.dock_approach: POI name 'dock_approach' already used",
    ),
    (
        "a known labware type",
        lambda d: d["plates"][0].update(type="deep_well"),
        "plates[0].type: unknown labware type 'deep_well'",
    ),
    (
        "an existing station",
        lambda d: d["plates"][0].update(station="nowhere"),
        "plates[0].station: unknown station 'nowhere'",
    ),
    (
        "an existing nest",
        lambda d: d["plates"][0].update(sub_position=3),
        "plates[0].sub_position: 3 is outside 1 .. 2",
    ),
    (
        "an existing hotel slot",
        lambda d: (d["robot"].update(hotel_slots=1), add_plate(hotel_slot=2)(d)),
        "plates[1].hotel_slot: 2 is outside 1 .. 1",
    ),
    (
        "a nest or a slot",
        lambda d: d["plates"][0].update(hotel_slot=1),
        "plates[0]: give either hotel_slot or station and sub_position, not both",
    ),
    ("somewhere", add_plate(), "plates[1].station: missing (or give hotel_slot)"),
    (
        "one plate per nest",
        add_plate(station="station_a", sub_position=1),
        "plates[1]: ('station_a', 1) already holds a plate",
    ),
    (
        "one plate per slot",
        lambda d: (
            add_plate(hotel_slot=2)(d),
            d["plates"].append({"id": "p3", "type": "sbs_microplate_96", "hotel_slot": 2}),
        ),
        "plates[2]: ('hotel', 2) already holds a plate",
    ),
    (
        "unique plate ids",
        lambda d: d["plates"].append({"id": "plate_001", "type": "sbs_microplate_96", "hotel_slot": 1}),
        "plates[1].id: duplicate plate id 'plate_001'",
    ),
]


@pytest.mark.parametrize(("rule", "mutate", "expected"), RULES, ids=[rule for rule, _, _ in RULES])
def test_each_rule_names_the_file_the_field_and_the_problem(
    tmp_path: Path, rule: str, mutate: Mutation, expected: str
) -> None:
    problems = problems_of(tmp_path, mutate)
    assert expected in problems, f"{rule}: {problems}"
    if rule != "somewhere":  # that one also misses its sub_position
        assert problems == [expected]


def test_every_problem_is_reported_top_to_bottom_not_only_the_first(tmp_path: Path) -> None:
    def many(d: dict[str, Any]) -> None:
        d["floor_size"] = "big"
        station(0, "nests")(d)["spacng"] = 0.1
        station(1, "marker")(d)["id"] = 3
        d["plates"][0]["type"] = "nope"

    assert problems_of(tmp_path, many) == [
        "floor_size: expected a number, got 'big'",
        "stations[0].nests.spacng: unknown key; did you mean 'spacing'?",
        "stations[1].marker.id: marker id 3 already used",
        "plates[0].type: unknown labware type 'nope'",
    ]


def test_rules_across_fields_still_run_where_the_schema_refused_a_part(tmp_path: Path) -> None:
    def broken(d: dict[str, Any]) -> None:
        station(0, "table")(d)["size"] = "wide"  # the schema refuses station 0 ...
        d["stations"][1]["name"] = "station_a"  # ... and station 1 still may not repeat its name
        d["plates"][0]["sub_position"] = 0  # a range the schema reports once, not again per station

    assert problems_of(tmp_path, broken) == [
        "stations[0].table.size: expected a list of 3 numbers, got 'wide'",
        "stations[1].name: duplicate station name 'station_a'",
        "plates[0].sub_position: 0 is outside 1 .. 20",
    ]


def test_a_file_that_is_no_mapping_or_no_yaml_or_absent_names_the_file(tmp_path: Path) -> None:
    listed = write(tmp_path, [1, 2])
    with pytest.raises(WorldError, match=rf"^{listed}: top level: expected a mapping, got list$"):
        load_world(listed)
    broken = tmp_path / "broken.yaml"
    broken.write_text("stations: [unclosed\n")
    with pytest.raises(WorldError) as caught:
        load_world(broken)
    assert len(caught.value.problems) == 1 and caught.value.problems[0].startswith(
        f"{broken}: not valid YAML:"
    )
    with pytest.raises(WorldError, match="cannot read"):
        load_world(tmp_path / "absent.yaml")


def test_optional_keys_take_their_documented_defaults(tmp_path: Path) -> None:
    data = default_data()
    for key in ("name", "floor_size", "pois", "plates"):
        data.pop(key)
    data["dock"].pop("approach_distance")
    data["robot"] = {}
    for item in data["stations"]:
        item["marker"].pop("rpy")
        item["nests"].pop("site_in_marker_rpy")
        for key in ("spacing", "approach_height"):
            item["nests"].pop(key)
        for key in ("work_standoff", "lateral"):
            item["poi"].pop(key)
    world = load_world(write(tmp_path, data), check_robot=False)  # defaults, not a servable lab
    assert (world.name, world.floor_size, world.hotel_slots, dict(world.plates)) == ("lab", 12.0, 2, {})
    assert world.start_docked and set(world.pois) == {"dock_approach", "station_a_work", "station_b_work"}
    assert world.pois["dock_approach"].x == pytest.approx(data["dock"]["pose"][0] + 0.6)
    first = world.stations[0]
    assert (first.marker_rpy, first.site_rpy, first.spacing, first.approach_height) == (
        (0, 0, 0),
        (0, 0, 0),
        0.0,
        0.1,
    )
    # only the standoff given: the final approach ends there; sideways, the row centred in the arm's band
    assert (first.work_standoff, first.lateral) == (first.standoff, 0.225)


def test_angles_are_degrees_in_the_file_and_radians_in_the_world() -> None:
    world = load_world()
    station_b = world.station("station_b")
    assert station_b.table_pose.yaw == pytest.approx(math.pi / 2)
    assert station_b.marker_rpy == pytest.approx((math.pi / 2, 0.0, -math.pi / 2))


def test_every_field_of_the_schema_is_described() -> None:
    schema = world_schema.json_schema()
    undescribed = [
        f"{name}.{key}"
        for name, part in [("top level", schema), *schema["$defs"].items()]
        for key, field in part.get("properties", {}).items()
        if not (field.get("description") or "$ref" in field)
    ]
    assert undescribed == []


def test_the_shipped_json_schema_is_what_the_definition_generates() -> None:
    """Fix a failure with `python -m lab_description.world_schema --write`."""
    assert world_schema.SCHEMA_FILE.read_text() == world_schema.schema_text(), (
        "lab_description/worlds/world.schema.json is stale: "
        "run `python -m lab_description.world_schema --write`"
    )


def test_shipped_worlds_point_editors_at_the_schema() -> None:
    for path in sorted(world_schema.SCHEMA_FILE.parent.glob("*.yaml")):
        assert path.read_text().splitlines()[0] == "# yaml-language-server: $schema=world.schema.json", path
