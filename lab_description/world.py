"""The lab as data: stations, markers, nests, POIs, labware and the robot start, read from one YAML file.

Why: nothing else hard-codes a station, a POI or a marker id; moving a station is a YAML edit.
The file's schema is `world_schema`, one definition from which the loader, its messages and the
JSON Schema lab_description/worlds/world.schema.json come; README.md, "The world file", explains it.
Everything here is frozen and pure (no PyBullet), so any thread may read a World. What the world
holds is named in the labware model (`labware_model`): its labware types are `LabwareType`s, a
station's nests are `Nest`s, and its plates are `Plate`s, each in a `Nest` or a `HotelSlot`; this
module adds the geometry (poses and sizes of tables, markers and nest sites).

Frames: ``table`` frame on the table top centre (x away from the robot's working side, z up);
``marker`` frame as OpenCV ArUco (x right, y up, z out of the face); ``site`` frame of a nest on
the nest floor centre where the plate's bottom centre rests (x along the plate's long side, z up).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from lab_description import world_schema as schema
from lab_description.station_placement import working_poses
from lab_description.world_obstacles import (
    Bench,
    Obstacle,
    bench_overlap_problems,
    dock_path_points,
    placement_problems,
)
from lab_description.world_rules import check
from lab_description.world_schema import MARKER_DICTIONARY_SIZE, MIRROR_AMBIGUOUS_MARKER_IDS
from labware_model.holders import HotelSlot, Nest
from labware_model.labware import LabwareType, Plate
from labware_model.workcell import STOCK_SENSORS, LabSensors, StationDescription, WorkcellDescription
from tiago_description import transforms as tf

__all__ = [
    "DEFAULT_WORLD",
    "MARKER_DICTIONARY_SIZE",
    "MIRROR_AMBIGUOUS_MARKER_IDS",
    "Obstacle",
    "Pose2D",
    "Station",
    "World",
    "WorldError",
    "load_world",
    "world_from_raw",
]

DEFAULT_WORLD = Path(__file__).resolve().parent / "worlds" / "default.yaml"


class WorldError(ValueError):
    """An invalid world file. The message has one line per problem, each naming the file, the field
    and what is wrong (`lab.yaml: stations[1].marker.id: id 17 also decodes when mirrored; ...`);
    `problems` holds the same lines."""

    def __init__(self, problems: list[str]) -> None:
        super().__init__("\n".join(problems))
        self.problems = tuple(problems)


@dataclass(frozen=True)
class Pose2D:
    """A pose on the floor: x, y (m) and heading yaw (rad)."""

    x: float
    y: float
    yaw: float

    def matrix(self, z: float = 0.0) -> np.ndarray:
        return tf.from_planar(self.x, self.y, self.yaw, z)


STATION_PLACEMENT_FIELDS = ("standoff", "work_standoff", "lateral", "approach_height")
MARKER_BOARD_SCALE = 1.4
"""The marker's board is this many times the marker's side wide, standing on the bench top behind
the marker (physics.scene builds it; the skills keep the arm clear of it)."""
MARKER_BOARD_THICKNESS = 0.01
MARKER_BOARD_BEHIND = 0.006
"""The board's middle lies this far behind the marker's face (m)."""


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
    placement_from_file: frozenset[str] = frozenset(STATION_PLACEMENT_FIELDS)
    """Which of standoff, work_standoff, lateral and approach_height the world file set; the robot
    chose the others (`lab_description.station_placement`)."""

    def nests(self) -> tuple[Nest, ...]:
        """Its nests, sub-position 1 first."""
        return tuple(Nest(self.name, sub_position) for sub_position in range(1, self.sub_positions + 1))

    def T_world_table(self) -> np.ndarray:
        return self.table_pose.matrix(self.table_size[2])

    def marker_stand_height(self) -> float:
        """How far the marker's board reaches above the bench top (m)."""
        return self.marker_xyz[2] + self.marker_size * MARKER_BOARD_SCALE / 2

    def marker_board_size(self) -> tuple[float, float, float]:
        """The marker's board (m): its width and height in the marker's plane, and its thickness."""
        return (self.marker_size * MARKER_BOARD_SCALE, self.marker_stand_height(), MARKER_BOARD_THICKNESS)

    def T_marker_board(self) -> np.ndarray:
        """The board's centre in the marker frame (x right, y up, z out of the face): it stands on the
        bench top, behind the marker."""
        up = self.marker_stand_height() / 2 - self.marker_xyz[2]
        return tf.make_transform((0.0, up, -MARKER_BOARD_BEHIND))

    def top_height(self) -> float:
        """The highest point of the bench and what stands on it (the marker's board), above the floor."""
        return self.table_size[2] + max(0.0, self.marker_stand_height())

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
    obstacles: tuple[Obstacle, ...] = ()
    """Free-standing boxes and cylinders on the floor (world_obstacles)."""
    sensors: LabSensors = LabSensors()
    """Lab-added plate sensors the robot's checks may read (a stock TIAGo++ has none)."""

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
            sensors=self.sensors,
        )


def with_stock_sensors(world: World) -> World:
    """The lab as a stock TIAGo++ meets it: none of the lab-added plate sensors."""
    return dataclasses.replace(world, sensors=STOCK_SENSORS)


def load_world(path: str | Path = DEFAULT_WORLD, *, check_robot: bool = True) -> World:
    """Read and validate a world file; raises WorldError listing every problem, each with the file and
    the field. `check_robot`: also refuse what the TIAGo++ cannot serve (`serviceability`: a bench
    under the base or in the tray's turning circle, a nest out of reach, a marker out of view)."""
    source = str(path)
    try:
        raw = yaml.safe_load(Path(path).read_text())
    except OSError as error:
        raise WorldError([f"{source}: cannot read: {error}"]) from error
    except yaml.YAMLError as error:
        raise WorldError([f"{source}: not valid YAML: {' '.join(str(error).split())}"]) from error
    return world_from_raw(raw, source, Path(path).stem, check_robot=check_robot)


def world_from_raw(raw: Any, source: str, default_name: str = "lab", *, check_robot: bool = True) -> World:
    """The checks of `load_world` on an already parsed file (a generated layout, say); `source` names
    it in the messages."""
    model, problems = check(raw)
    if model is None:
        raise WorldError([problem.line(source) for problem in problems])
    from lab_description.serviceability import place_station  # pinocchio: the robot model's reach

    def place(station: Station, tallest: float) -> Station:
        return place_station(station, tallest, reach=check_robot)

    world = _world(model, source, default_name=default_name, place=place)
    placement = _bench_placement_problems(world) + _obstacle_placement_problems(world)
    if placement:
        raise WorldError([f"{source}: {where}: {what}" for where, what in placement])
    if check_robot:
        from lab_description.serviceability import service_problems  # pinocchio: only when checking

        refused = service_problems(world)
        if refused:
            raise WorldError([f"{source}: {problem.where}: {problem.what}" for problem in refused])
    return world


def _benches(world: World) -> list[Bench]:
    return [
        Bench(s.name, s.table_pose.x, s.table_pose.y, s.table_pose.yaw, s.table_size[0], s.table_size[1])
        for s in world.stations
    ]


def _bench_placement_problems(world: World) -> list[tuple[str, str]]:
    """No two benches in the same place (`world_obstacles.bench_overlap_problems`)."""
    return [(f"stations[{j}].table.pose", what) for j, what in bench_overlap_problems(_benches(world))]


def _obstacle_placement_problems(world: World) -> list[tuple[str, str]]:
    """Obstacles inside the floor, off the benches, clear of where the robot stands and turns."""
    if not world.obstacles:
        return []
    keep_clear = {f"POI {name!r}": (pose.x, pose.y) for name, pose in world.pois.items()}
    keep_clear["the docked pose"] = (world.dock_pose.x, world.dock_pose.y)
    dock_poi = world.pois[world.dock_poi]
    keep_clear.update(dock_path_points((world.dock_pose.x, world.dock_pose.y), (dock_poi.x, dock_poi.y)))
    for station in world.stations:
        for label, pose in working_poses(station):
            keep_clear[f"{station.name}'s {label.removeprefix('the ')}"] = (pose.x, pose.y)
    return placement_problems(world.obstacles, world.floor_size, _benches(world), keep_clear)


def _obstacle(item: schema.Obstacle) -> Obstacle:
    pose = _pose(item.pose)
    length, width = item.size or (0.0, 0.0)
    return Obstacle(item.name, pose.x, pose.y, pose.yaw, length, width, item.radius or 0.0, item.height)


def _pose(values: tuple[float, float, float]) -> Pose2D:
    x, y, yaw_deg = values
    return Pose2D(x, y, math.radians(yaw_deg))


def _radians(values: tuple[float, float, float]) -> tuple[float, float, float]:
    roll, pitch, yaw = (math.radians(v) for v in values)
    return (roll, pitch, yaw)


def station_from_raw(raw: Any, tallest_labware_m: float, *, reach: bool = False) -> Station | None:
    """One station's mapping as the program reads it, placed for labware up to `tallest_labware_m`
    high (with `reach`, its approach height chosen against the arm's reach, else the preferred), or
    None if it breaks the schema; none of the checks that need the rest of the lab (a layout
    generator's look at a candidate)."""
    try:
        item = schema.Station.model_validate(raw)
    except ValueError:  # pydantic's ValidationError
        return None
    from lab_description.serviceability import place_station

    return place_station(_station(item), tallest_labware_m, reach=reach)


def _station(item: schema.Station) -> Station:
    """The station as the file gives it; the placement fields it leaves out are 0 until placed."""
    poi = item.poi
    given = {
        "standoff": poi.standoff,
        "work_standoff": poi.work_standoff,
        "lateral": poi.lateral,
        "approach_height": item.nests.approach_height,
    }
    return Station(
        name=item.name,
        table_pose=_pose(item.table.pose),
        table_size=item.table.size,
        marker_id=item.marker.id,
        marker_size=item.marker.size,
        marker_xyz=item.marker.xyz,
        marker_rpy=_radians(item.marker.rpy),
        site_xyz=item.nests.site_in_marker_xyz,
        site_rpy=_radians(item.nests.site_in_marker_rpy),
        sub_positions=item.nests.sub_positions,
        spacing=item.nests.spacing,
        nest_clearance=item.nests.clearance,
        poi=poi.name or f"{item.name}_work",
        standoff=poi.standoff or 0.0,
        lateral=poi.lateral or 0.0,
        approach_height=item.nests.approach_height or 0.0,
        work_standoff=poi.work_standoff or poi.standoff or 0.0,
        placement_from_file=frozenset(name for name, value in given.items() if value is not None),
    )


def _world(model: schema.WorldFile, source: str, default_name: str, place: Any) -> World:
    """The validated file in the program's words: dataclasses, radians, the labware model. `place`
    chooses what the file leaves to the robot (station, tallest labware height -> Station)."""
    dock_pose = _pose(model.dock.pose)
    distance = model.dock.approach_distance
    pois = {
        model.dock.poi: Pose2D(
            dock_pose.x + distance * math.cos(dock_pose.yaw),
            dock_pose.y + distance * math.sin(dock_pose.yaw),
            dock_pose.yaw,
        ),
        **{name: _pose(pose) for name, pose in model.pois.items()},
    }
    tallest = max((t.height for t in model.labware_types.values()), default=0.0)
    stations = tuple(place(_station(item), tallest) for item in model.stations)
    pois.update({station.poi: station.work_pose() for station in stations})
    plates: dict[Plate, Nest | HotelSlot] = {}
    for item in model.plates:
        holder = (
            HotelSlot(item.hotel_slot)
            if item.hotel_slot is not None
            else Nest(str(item.station), int(item.sub_position or 0))
        )
        plates[Plate(item.id, item.type)] = holder
    return World(
        source,
        dock_pose,
        model.dock.poi,
        pois,
        stations,
        {
            name: LabwareType(name, t.length, t.width, t.height, t.mass)
            for name, t in model.labware_types.items()
        },
        plates,
        True,
        model.robot.hotel_slots,
        model.floor_size,
        name=model.name or default_name,
        obstacles=tuple(_obstacle(item) for item in model.obstacles),
        sensors=LabSensors(model.sensors.nests, model.sensors.hotel, model.sensors.label_readers),
    )
