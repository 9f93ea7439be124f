"""Checking a world file: the schema's findings in the reader's words, and the rules across fields.

Why a module of its own: pydantic words its errors for programmers ("Input should be a valid
number"); a technician editing a lab file needs the field's path and what to write instead
("stations[0].nests.spacng: unknown key; did you mean 'spacing'?"). Every problem is reported, not
the first only: the schema's, and those of the rules no JSON Schema can state (unique names across
the file, plates on nests that exist). Those read the raw file defensively, so they run even where
the schema refused a part; a field the schema already refused gets no second message.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from pydantic import ValidationError

from lab_description.world_schema import WorldFile, json_schema


@dataclass(frozen=True)
class Problem:
    """One thing wrong in a world file: where (a dotted path such as `stations[1].marker.id`) and what."""

    where: str
    what: str

    def line(self, source: str) -> str:
        return f"{source}: {self.where}: {self.what}"


def check(raw: Any) -> tuple[WorldFile | None, list[Problem]]:
    """Validate a parsed world file: the model if nothing is wrong, and every problem found."""
    if not isinstance(raw, dict):
        return None, [Problem("top level", f"expected a mapping, got {type(raw).__name__}")]
    model, problems = None, []
    try:
        model = WorldFile.model_validate(raw)
    except ValidationError as error:
        problems = _schema_problems(error, raw)
    refused = {problem.where for problem in problems}
    problems += [problem for problem in _cross_field_problems(raw) if problem.where not in refused]
    problems.sort(key=lambda problem: _file_order(raw, problem.where))
    return (None if problems else model), problems


def path_of(loc: tuple[Any, ...]) -> str:
    """('stations', 0, 'marker', 'id') -> 'stations[0].marker.id'."""
    text = ""
    for part in loc:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "top level"


def _file_order(raw: Any, where: str) -> list[int]:
    """Where a path comes in the file: problems are listed top to bottom (a missing key last in its
    mapping)."""
    order = []
    for part in re.findall(r"[^.\[\]]+|\[\d+\]", where):
        if part.startswith("["):
            index = int(part[1:-1])
            order.append(index)
            raw = raw[index] if isinstance(raw, list) and index < len(raw) else None
        else:
            keys = [str(key) for key in raw] if isinstance(raw, dict) else []
            order.append(keys.index(part) if part in keys else len(keys))
            raw = raw.get(part) if isinstance(raw, dict) else None
    return order


def _schema_problems(error: ValidationError, raw: dict) -> list[Problem]:
    problems: list[Problem] = []
    for detail in error.errors():
        loc = tuple(detail["loc"])
        vector = _vector_prefix(loc[:-1])  # inside a vector, not the vector itself
        if vector is None and detail["type"] != "missing":
            vector = _vector_prefix(loc)
        if vector is not None:  # one message for a malformed [x, y, z], not one per entry
            length = len(_schema_at(vector)["prefixItems"])
            problem = Problem(path_of(vector), _vector_message(_raw_at(raw, vector), length))
        else:
            problem = Problem(path_of(loc), _message(detail, loc))
        if problem not in problems:
            problems.append(problem)
    return problems


def _message(detail: dict[str, Any], loc: tuple[Any, ...]) -> str:
    kind, value = detail["type"], detail.get("input")
    if kind == "missing":
        return "missing"
    if kind == "extra_forbidden":
        return _unknown_key(str(loc[-1]), sorted(_schema_at(loc[:-1]).get("properties", {})))
    if kind in ("model_type", "dict_type"):
        return f"expected a mapping, got {type(value).__name__}"
    if kind == "list_type":
        return f"expected a list, got {value!r}"
    if kind == "too_short" and isinstance(value, list):
        return "expected a non-empty list"
    if kind in ("float_type", "finite_number"):
        return f"expected a number, got {value!r}"
    if kind == "int_type":
        return f"expected an integer, got {value!r}"
    if kind in ("string_type", "string_too_short"):
        return f"expected a non-empty string, got {value!r}"
    if kind in ("greater_than_equal", "less_than_equal", "greater_than"):
        schema = _schema_at(loc)
        return f"{value} is outside {schema.get('minimum', '-inf')} .. {schema.get('maximum', 'inf')}"
    if kind == "literal_error":
        return f"expected {detail['ctx']['expected']}, got {value!r}"
    if kind == "value_error":
        return str(detail["ctx"]["error"])
    return detail["msg"]


def _unknown_key(key: str, known: list[str]) -> str:
    close = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
    if close:
        return f"unknown key; did you mean {close[0]!r}?"
    return f"unknown key; expected one of {', '.join(known)}" if known else "unknown key"


def _vector_message(value: Any, length: int = 3) -> str:
    if isinstance(value, list) and len(value) == length and all(_is_number(v) for v in value):
        return f"all sizes must be positive, got {value!r}"  # the only vectors with a range: sizes
    return f"expected a list of {length} numbers, got {value!r}"


_ROOT = json_schema()


def _resolve(schema: dict[str, Any]) -> dict[str, Any]:
    while "$ref" in schema:
        schema = _ROOT["$defs"][schema["$ref"].rsplit("/", 1)[-1]]
    for branch in schema.get("anyOf", ()):  # `X | None`: the X
        if branch.get("type") != "null":
            return _resolve(branch)
    return schema


def _schema_at(loc: tuple[Any, ...]) -> dict[str, Any]:
    """The part of the JSON Schema describing the value at `loc` ({} if the path leaves it)."""
    schema = _resolve(_ROOT)
    for part in loc:
        if "prefixItems" in schema and isinstance(part, int):
            schema = schema["prefixItems"][part] if part < len(schema["prefixItems"]) else {}
        elif "items" in schema:
            schema = schema["items"]
        elif isinstance(schema.get("additionalProperties"), dict):
            schema = schema["additionalProperties"]
        else:
            schema = schema.get("properties", {}).get(part, {})
        schema = _resolve(schema)
    return schema


def _vector_prefix(loc: tuple[Any, ...]) -> tuple[Any, ...] | None:
    for end in range(len(loc) + 1):
        if "prefixItems" in _schema_at(loc[:end]):
            return loc[:end]
    return None


def _raw_at(raw: Any, loc: tuple[Any, ...]) -> Any:
    for part in loc:
        try:
            raw = raw[part]
        except (KeyError, IndexError, TypeError):
            return None
    return raw


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _is_index(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _entries(raw: dict, key: str) -> Iterator[tuple[int, dict]]:
    """The list `key`'s mappings with their indices; whatever is malformed the schema reports."""
    items = raw.get(key)
    for i, item in enumerate(items if isinstance(items, list) else ()):
        if isinstance(item, dict):
            yield i, item


def _sub(item: dict, key: str) -> dict:
    value = item.get(key)
    return value if isinstance(value, dict) else {}


def _cross_field_problems(raw: dict) -> list[Problem]:
    return _unique_names(raw) + _plate_problems(raw) + _obstacle_shape_problems(raw)


def _obstacle_shape_problems(raw: dict) -> list[Problem]:
    """A box gives size, a cylinder radius (not both); obstacle names are unique."""
    problems: list[Problem] = []
    names: set[Any] = set()
    for i, obstacle in _entries(raw, "obstacles"):
        where = f"obstacles[{i}]"
        shape = obstacle.get("shape")
        needed, other = {"box": ("size", "radius"), "cylinder": ("radius", "size")}.get(shape, (None, None))
        if needed is not None and needed not in obstacle:
            problems.append(Problem(f"{where}.{needed}", f"missing: a {shape} needs {needed}"))
        if other is not None and other in obstacle:
            problems.append(Problem(f"{where}.{other}", f"a {shape} has no {other}; give {needed} only"))
        name = obstacle.get("name")
        if isinstance(name, str) and name in names:
            problems.append(Problem(f"{where}.name", f"duplicate obstacle name {name!r}"))
        names.add(name if isinstance(name, str) else None)
    return problems


def _unique_names(raw: dict) -> list[Problem]:
    problems = []
    poi_names: set[Any] = set()
    dock_poi = _sub(raw, "dock").get("poi")
    if isinstance(dock_poi, str):
        poi_names.add(dock_poi)
    for name in _sub(raw, "pois"):
        if name in poi_names:
            problems.append(Problem(f"pois.{name}", f"POI name {name!r} already used"))
        poi_names.add(name if isinstance(name, str) else None)
    names: set[Any] = set()
    marker_ids: set[Any] = set()
    for i, station in _entries(raw, "stations"):
        name, marker_id, poi = station.get("name"), _sub(station, "marker").get("id"), _sub(station, "poi")
        if isinstance(name, str) and name in names:
            problems.append(Problem(f"stations[{i}].name", f"duplicate station name {name!r}"))
        if _is_index(marker_id) and marker_id in marker_ids:
            problems.append(Problem(f"stations[{i}].marker.id", f"marker id {marker_id} already used"))
        poi_name = poi.get("name", f"{name}_work" if isinstance(name, str) else None)
        if isinstance(poi_name, str) and poi_name in poi_names:
            problems.append(Problem(f"stations[{i}].poi.name", f"POI name {poi_name!r} already used"))
        names.add(name if isinstance(name, str) else None)
        marker_ids.add(marker_id if _is_index(marker_id) else None)
        poi_names.add(poi_name if isinstance(poi_name, str) else None)
    return problems


def _plate_problems(raw: dict) -> list[Problem]:
    """Each plate's type exists, it starts in a nest or hotel slot that exists, alone, and its id is new."""
    types = raw.get("labware_types") if isinstance(raw.get("labware_types"), dict) else {}
    nests = {
        s["name"]: _sub(s, "nests").get("sub_positions")
        for _, s in _entries(raw, "stations")
        if isinstance(s.get("name"), str)
    }
    slots = _sub(raw, "robot").get("hotel_slots", 2)
    problems: list[Problem] = []
    holders: set[tuple[Any, Any] | None] = set()
    ids: set[Any] = set()
    for i, plate in _entries(raw, "plates"):
        where = f"plates[{i}]"
        kind = plate.get("type")
        if isinstance(kind, str) and kind not in types:
            problems.append(Problem(f"{where}.type", f"unknown labware type {kind!r}"))
        holder = _holder(plate, where, nests, slots, problems)
        if holder is not None and holder in holders:
            problems.append(Problem(where, f"{holder} already holds a plate"))
        holders.add(holder)
        plate_id = plate.get("id")
        if isinstance(plate_id, str) and plate_id in ids:
            problems.append(Problem(f"{where}.id", f"duplicate plate id {plate_id!r}"))
        ids.add(plate_id if isinstance(plate_id, str) else None)
    return problems


def _holder(
    plate: dict, where: str, nests: dict[Any, Any], slots: Any, problems: list[Problem]
) -> tuple[Any, Any] | None:
    """Where the plate starts as the messages have always shown it: ('hotel', 2), ('station_a', 1)."""
    if "hotel_slot" in plate:
        if "station" in plate or "sub_position" in plate:
            problems.append(Problem(where, "give either hotel_slot or station and sub_position, not both"))
            return None
        slot = plate["hotel_slot"]
        if not _is_index(slot):
            return None
        if _is_index(slots) and not 1 <= slot <= slots:
            problems.append(Problem(f"{where}.hotel_slot", f"{slot} is outside 1 .. {slots}"))
            return None
        return ("hotel", slot)
    missing = [key for key in ("station", "sub_position") if key not in plate]
    problems.extend(Problem(f"{where}.{key}", "missing (or give hotel_slot)") for key in missing)
    station, sub_position = plate.get("station"), plate.get("sub_position")
    if missing or not isinstance(station, str) or not _is_index(sub_position):
        return None
    if station not in nests:
        problems.append(Problem(f"{where}.station", f"unknown station {station!r}"))
        return None
    count = nests[station]
    if _is_index(count) and not 1 <= sub_position <= count:
        problems.append(Problem(f"{where}.sub_position", f"{sub_position} is outside 1 .. {count}"))
        return None
    return (station, sub_position)
