"""The lab as data: stations, markers, nests, POIs, labware and the robot start, read from one YAML file.

Why: nothing else hard-codes a station, a POI or a marker id; moving a station is a YAML edit.
The schema is documented in README.md, "The world file". Everything here is frozen and pure (no
PyBullet), so any thread may read a World. What the world holds is named in the labware model
(`labware_model`): its labware types are `LabwareType`s, a station's nests are `Nest`s, and its
plates are `Plate`s, each in a `Nest` or a `HotelSlot`; this module adds the geometry (poses and
sizes of tables, markers and nest sites).

Frames: ``table`` frame on the table top centre (x away from the robot's working side, z up);
``marker`` frame as OpenCV ArUco (x right, y up, z out of the face); ``site`` frame of a nest on
the nest floor centre where the plate's bottom centre rests (x along the plate's long side, z up).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from labware_model.holders import HotelSlot, Nest
from labware_model.labware import LabwareType, Plate
from labware_model.workcell import StationDescription, WorkcellDescription
from tiago_sim import transforms as tf

DEFAULT_WORLD = Path(__file__).resolve().parents[1] / "worlds" / "default.yaml"
MIRROR_AMBIGUOUS_MARKER_IDS = frozenset({8, 9, 17, 47})
MARKER_DICTIONARY_SIZE = 50  # DICT_4X4_50


class WorldError(ValueError):
    """An invalid world file; the message names the file, the field and the problem."""


@dataclass(frozen=True)
class Pose2D:
    """A pose on the floor: x, y (m) and heading yaw (rad)."""

    x: float
    y: float
    yaw: float

    def matrix(self, z: float = 0.0) -> np.ndarray:
        return tf.from_planar(self.x, self.y, self.yaw, z)


@dataclass(frozen=True)
class Station:
    """A table with an ArUco marker and a row of nests (sub-positions 1..n)."""

    name: str
    table_pose: Pose2D
    table_size: tuple[float, float, float]  # depth (x), width (y), height (top surface above floor)
    marker_id: int
    marker_size: float
    marker_xyz: tuple[float, float, float]  # marker centre in the table frame
    marker_rpy: tuple[float, float, float]
    site_xyz: tuple[float, float, float]  # sub-position 1 in the marker frame
    site_rpy: tuple[float, float, float]
    sub_positions: int
    spacing: float  # between sub-positions along the site x axis
    nest_clearance: float  # per side, between plate and nest walls
    poi: str
    standoff: float  # navigation stops base_footprint this far in front of the middle of the nest row
    lateral: float  # and this far to the side, so the site lies on the working arm's side
    approach_height: float  # site_approach is this far above the site
    work_standoff: float = 0.0  # the marker-guided final approach ends this close (0: same as standoff)

    def nests(self) -> tuple[Nest, ...]:
        """Its nests, sub-position 1 first."""
        return tuple(Nest(self.name, sub_position) for sub_position in range(1, self.sub_positions + 1))

    def T_world_table(self) -> np.ndarray:
        return self.table_pose.matrix(self.table_size[2])

    def T_table_marker(self) -> np.ndarray:
        return tf.from_xyz_rpy(self.marker_xyz, self.marker_rpy)

    def T_world_marker(self) -> np.ndarray:
        return self.T_world_table() @ self.T_table_marker()

    def T_marker_site(self, sub_position: int) -> np.ndarray:
        """Nest frame of a sub-position (1-based) in the marker frame."""
        if not 1 <= sub_position <= self.sub_positions:
            raise KeyError(f"station {self.name!r} has no sub-position {sub_position}")
        first = tf.from_xyz_rpy(self.site_xyz, self.site_rpy)
        return first @ tf.make_transform(((sub_position - 1) * self.spacing, 0.0, 0.0))

    def T_marker_site_approach(self, sub_position: int) -> np.ndarray:
        return self.T_marker_site(sub_position) @ tf.make_transform((0.0, 0.0, self.approach_height))

    def T_world_site(self, sub_position: int) -> np.ndarray:
        return self.T_world_marker() @ self.T_marker_site(sub_position)

    def work_pose(self) -> Pose2D:
        """Where navigation brings base_footprint (the POI): facing the nests, ``standoff`` in front of
        their middle, far enough from the table that a navigation error never makes the base touch it."""
        return self._pose_in_front(self.standoff)

    def aligned_pose(self) -> Pose2D:
        """Where base_footprint works: ``work_standoff`` in front of the nests, reached from the POI by
        a short drive guided by the station's marker."""
        return self._pose_in_front(self.work_standoff or self.standoff)

    def _pose_in_front(self, standoff: float) -> Pose2D:
        middle = (
            self.T_world_marker()
            @ self.T_marker_site(1)
            @ tf.make_transform(((self.sub_positions - 1) * self.spacing / 2, 0.0, 0.0))
        )
        facing = tf.yaw_of(self.T_world_table())
        forward = np.array([math.cos(facing), math.sin(facing)])
        left = np.array([-forward[1], forward[0]])
        xy = middle[:2, 3] - standoff * forward + self.lateral * left
        return Pose2D(float(xy[0]), float(xy[1]), facing)


@dataclass(frozen=True)
class World:
    source: str
    dock_pose: Pose2D  # base_footprint pose when docked (facing away from the dock)
    dock_poi: str
    pois: Mapping[str, Pose2D]
    stations: tuple[Station, ...]
    labware_types: Mapping[str, LabwareType]
    plates: Mapping[Plate, Nest | HotelSlot]  # where each plate starts, in the file's order
    start_docked: bool
    hotel_slots: int = 2
    floor_size: float = 12.0
    extras: Mapping[str, Any] = field(default_factory=dict)
    name: str = ""
    """The lab's name (optional in the file): the SiLA servers carry it in their names."""

    def station(self, name: str) -> Station:
        for station in self.stations:
            if station.name == name:
                return station
        raise KeyError(f"unknown station {name!r}")

    def describe_workcell(self) -> WorkcellDescription:
        """What the robot serves in this world (the answer of /describe_workcell)."""
        return WorkcellDescription(
            stations=tuple(StationDescription(s.name, s.sub_positions, s.poi) for s in self.stations),
            hotel_slots=self.hotel_slots,
            pois=tuple(sorted(self.pois)),
            dock_poi=self.dock_poi,
        )


class _Reader:
    """Walks the YAML tree and raises WorldError naming the file and the dotted field path."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, where: str, problem: str) -> WorldError:
        return WorldError(f"{self.source}: {where}: {problem}")

    def mapping(self, value: Any, where: str) -> dict:
        if not isinstance(value, dict):
            raise self.fail(where, f"expected a mapping, got {type(value).__name__}")
        return value

    def get(self, data: dict, key: str, where: str, default: Any = ...) -> Any:
        if key not in data:
            if default is ...:
                raise self.fail(f"{where}.{key}" if where else key, "missing")
            return default
        return data[key]

    def number(
        self,
        data: dict,
        key: str,
        where: str,
        low: float = -math.inf,
        high: float = math.inf,
        default: Any = ...,
    ) -> float:
        value = self.get(data, key, where, default)
        name = f"{where}.{key}" if where else key
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(name, f"expected a number, got {value!r}")
        if not low <= value <= high:
            raise self.fail(name, f"{value} is outside {low} .. {high}")
        return float(value)

    def integer(
        self, data: dict, key: str, where: str, low: int = 1, high: int = 10**6, default: Any = ...
    ) -> int:
        value = self.get(data, key, where, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(f"{where}.{key}", f"expected an integer, got {value!r}")
        if not low <= value <= high:
            raise self.fail(f"{where}.{key}", f"{value} is outside {low} .. {high}")
        return value

    def text(self, data: dict, key: str, where: str, default: Any = ...) -> str:
        value = self.get(data, key, where, default)
        if not isinstance(value, str) or not value:
            raise self.fail(f"{where}.{key}", f"expected a non-empty string, got {value!r}")
        return value

    def vector(
        self, data: dict, key: str, where: str, length: int = 3, default: Any = ...
    ) -> tuple[float, ...]:
        value = self.get(data, key, where, default)
        ok = isinstance(value, (list, tuple)) and len(value) == length
        if not ok or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            raise self.fail(f"{where}.{key}", f"expected a list of {length} numbers, got {value!r}")
        return tuple(float(v) for v in value)

    def pose2d(self, data: dict, key: str, where: str) -> Pose2D:
        x, y, yaw_deg = self.vector(data, key, where)
        return Pose2D(x, y, math.radians(yaw_deg))

    def rpy(self, data: dict, key: str, where: str) -> tuple[float, float, float]:
        return tuple(math.radians(v) for v in self.vector(data, key, where, default=[0, 0, 0]))


def _read_station(r: _Reader, raw: Any, where: str) -> Station:
    data = r.mapping(raw, where)
    table = r.mapping(r.get(data, "table", where), f"{where}.table")
    marker = r.mapping(r.get(data, "marker", where), f"{where}.marker")
    nests = r.mapping(r.get(data, "nests", where), f"{where}.nests")
    poi = r.mapping(r.get(data, "poi", where), f"{where}.poi")
    marker_id = r.integer(marker, "id", f"{where}.marker", 0, MARKER_DICTIONARY_SIZE - 1)
    if marker_id in MIRROR_AMBIGUOUS_MARKER_IDS:
        raise r.fail(f"{where}.marker.id", f"id {marker_id} also decodes when mirrored; avoid 8, 9, 17, 47")
    size = r.vector(table, "size", f"{where}.table")
    if min(size) <= 0:
        raise r.fail(f"{where}.table.size", "all sizes must be positive")
    standoff = r.number(poi, "standoff", f"{where}.poi", 0.3, 1.0)
    return Station(
        name=r.text(data, "name", where),
        table_pose=r.pose2d(table, "pose", f"{where}.table"),
        table_size=size,
        marker_id=marker_id,
        marker_size=r.number(marker, "size", f"{where}.marker", 0.10, 0.5),
        marker_xyz=r.vector(marker, "xyz", f"{where}.marker"),
        marker_rpy=r.rpy(marker, "rpy", f"{where}.marker"),
        site_xyz=r.vector(nests, "site_in_marker_xyz", f"{where}.nests"),
        site_rpy=r.rpy(nests, "site_in_marker_rpy", f"{where}.nests"),
        sub_positions=r.integer(nests, "sub_positions", f"{where}.nests", 1, 20),
        spacing=r.number(nests, "spacing", f"{where}.nests", 0.0, 2.0, default=0.0),
        nest_clearance=r.number(nests, "clearance", f"{where}.nests", 0.0005, 0.02),
        poi=r.text(poi, "name", f"{where}.poi"),
        standoff=standoff,
        lateral=r.number(poi, "lateral", f"{where}.poi", -0.5, 0.5, default=0.0),
        approach_height=r.number(nests, "approach_height", f"{where}.nests", 0.02, 0.4, default=0.1),
        work_standoff=r.number(poi, "work_standoff", f"{where}.poi", 0.3, 1.0, default=standoff),
    )


def load_world(path: str | Path = DEFAULT_WORLD) -> World:
    """Read and validate a world file; raises WorldError naming file, field and problem."""
    source = str(path)
    r = _Reader(source)
    try:
        raw = yaml.safe_load(Path(path).read_text())
    except OSError as error:
        raise WorldError(f"{source}: cannot read: {error}") from error
    except yaml.YAMLError as error:
        raise WorldError(f"{source}: not valid YAML: {error}") from error
    data = r.mapping(raw, "top level")
    dock = r.mapping(r.get(data, "dock", ""), "dock")
    dock_pose = r.pose2d(dock, "pose", "dock")
    dock_poi = r.text(dock, "poi", "dock")
    dock_distance = r.number(dock, "approach_distance", "dock", 0.3, 2.0, default=0.6)
    pois: dict[str, Pose2D] = {
        dock_poi: Pose2D(
            dock_pose.x + dock_distance * math.cos(dock_pose.yaw),
            dock_pose.y + dock_distance * math.sin(dock_pose.yaw),
            dock_pose.yaw,
        )
    }
    for name, value in r.mapping(r.get(data, "pois", "", {}), "pois").items():
        pois[str(name)] = r.pose2d({"pose": value}, "pose", f"pois.{name}")
    raw_stations = r.get(data, "stations", "")
    if not isinstance(raw_stations, list) or not raw_stations:
        raise r.fail("stations", "expected a non-empty list")
    stations = tuple(_read_station(r, raw, f"stations[{i}]") for i, raw in enumerate(raw_stations))
    seen_names: set[str] = set()
    seen_ids: set[int] = set()
    for i, station in enumerate(stations):
        if station.name in seen_names:
            raise r.fail(f"stations[{i}].name", f"duplicate station name {station.name!r}")
        if station.marker_id in seen_ids:
            raise r.fail(f"stations[{i}].marker.id", f"marker id {station.marker_id} already used")
        if station.poi in pois:
            raise r.fail(f"stations[{i}].poi.name", f"POI name {station.poi!r} already used")
        seen_names.add(station.name)
        seen_ids.add(station.marker_id)
        pois[station.poi] = station.work_pose()
    labware_types = {}
    for name, value in r.mapping(r.get(data, "labware_types", ""), "labware_types").items():
        where = f"labware_types.{name}"
        item = r.mapping(value, where)
        labware_types[str(name)] = LabwareType(
            str(name),
            r.number(item, "length", where, 0.01, 0.5),
            r.number(item, "width", where, 0.01, 0.5),
            r.number(item, "height", where, 0.002, 0.2),
            r.number(item, "mass", where, 0.01, 3.0),
        )
    hotel_slots = r.integer(
        r.mapping(r.get(data, "robot", ""), "robot"), "hotel_slots", "robot", 1, 2, default=2
    )
    plates = _read_plates(r, data, {s.name: s for s in stations}, labware_types, hotel_slots)
    robot = r.mapping(r.get(data, "robot", ""), "robot")
    start = r.get(robot, "start", "robot", "docked")
    if start != "docked":
        raise r.fail("robot.start", f"only 'docked' is supported, got {start!r}")
    return World(
        source,
        dock_pose,
        dock_poi,
        pois,
        stations,
        labware_types,
        plates,
        True,
        hotel_slots,
        r.number(data, "floor_size", "", 2.0, 100.0, default=12.0),
        name=r.text(data, "name", "", default=Path(path).stem),
    )


def _read_plates(
    r: _Reader, data: dict, stations: dict[str, Station], types: dict, hotel_slots: int
) -> dict[Plate, Nest | HotelSlot]:
    plates: dict[Plate, Nest | HotelSlot] = {}
    raw_plates = r.get(data, "plates", "", [])
    if not isinstance(raw_plates, list):
        raise r.fail("plates", "expected a list")
    for i, raw in enumerate(raw_plates):
        where = f"plates[{i}]"
        item = r.mapping(raw, where)
        labware_type = r.text(item, "type", where)
        if labware_type not in types:
            raise r.fail(f"{where}.type", f"unknown labware type {labware_type!r}")
        holder: Nest | HotelSlot
        if "hotel_slot" in item:
            holder = HotelSlot(r.integer(item, "hotel_slot", where, 1, hotel_slots))
        else:
            station = r.text(item, "station", where)
            if station not in stations:
                raise r.fail(f"{where}.station", f"unknown station {station!r}")
            holder = Nest(station, r.integer(item, "sub_position", where, 1, stations[station].sub_positions))
        plate = Plate(r.text(item, "id", where), labware_type)
        if holder in plates.values():
            raise r.fail(where, f"{_place_of(holder)} already holds a plate")
        if any(known.labware_id == plate.labware_id for known in plates):
            raise r.fail(f"{where}.id", f"duplicate plate id {plate.labware_id!r}")
        plates[plate] = holder
    return plates


def _place_of(holder: Nest | HotelSlot) -> tuple:
    """The holder as the world file's messages have always shown it: ('hotel', 2), ('station_a', 1)."""
    return ("hotel", holder.index) if isinstance(holder, HotelSlot) else (holder.station, holder.sub_position)
