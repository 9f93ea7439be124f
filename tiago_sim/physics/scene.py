"""Builds the static lab and the plates in a PyBullet client from a World.

Why separate from the robot: the lab is pure world data (floor, dock, tables, nests, markers,
plates); the Simulation adds the robot on top. Call on the thread that owns the client.
Nests are four corner L-brackets around a pocket (plate size + clearance) with 45 deg lead-in
chamfers of low friction, as real SBS nests have: a plate released a few millimetres or a degree
or two off centre slides into the pocket. The brackets leave the middle of the plate's long
sides free for the finger pads.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import pybullet as p

from lab_description.world import Obstacle, Station, World
from lab_description.world_obstacles import DOCK_SIZE, dock_box
from labware_model.holders import HotelSlot, Nest
from labware_model.labware import LabwareType
from tiago_description import transforms as tf
from tiago_description.hotel_model import corner_ramp_boxes
from tiago_sim.navigation.occupancy_map import WALL_THICKNESS
from tiago_sim.physics.gridded_box import GRID_CELL, gridded_box_visual
from tiago_sim.physics.marker_asset import marker_visual

log = logging.getLogger(__name__)

PLATE_FRICTION = 1.0
PLATE_SPINNING_FRICTION = 0.02
NEST_LEAD_IN = 0.006  # per side, 45 deg from the bench top: the opening is this much wider than the pocket
NEST_LEAD_IN_SLOPE = 1.0  # rise per run of the lead-in ramps: 45 deg (the rotations in nest_boxes)
NEST_RAMP_FOOT = 0.001  # the ramp runs on this far below the bench top: no edge is left at its foot
NEST_LEG_LENGTH = 0.015  # bracket legs run this far in from each corner
NEST_FRICTION = 0.15  # polished lead-ins: with the plate's 1.0, the pair's friction is 0.15
TABLE_FRICTION = 0.3  # laminate bench top: plate on table 0.3
FLOOR_RGBA = [0.85, 0.85, 0.85, 1.0]
WALL_HEIGHT = 1.0  # m: the floor's edge walls (the map's walls; the base laser sees them)


@dataclass
class Scene:
    """Body ids of what was built; ``plates`` maps labware id -> body id."""

    floor: int = -1
    dock: int = -1
    tables: dict[str, int] = field(default_factory=dict)
    nests: dict[Nest, int] = field(default_factory=dict)
    markers: dict[str, int] = field(default_factory=dict)
    marker_stands: dict[str, int] = field(default_factory=dict)
    obstacles: dict[str, int] = field(default_factory=dict)
    walls: dict[str, int] = field(default_factory=dict)
    plates: dict[str, int] = field(default_factory=dict)
    plate_types: dict[str, LabwareType] = field(default_factory=dict)


def _static_box(client: int, size, T_world_box: np.ndarray, rgba, collide: bool = True) -> int:
    """A static box; one larger than a grid cell is seen as a gridded mesh (cheaper to render)."""
    half = [s / 2 for s in size]
    collision = (
        p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client) if collide else -1
    )
    gridded = max(size) > GRID_CELL
    if gridded:
        visual = gridded_box_visual(client, half, rgba)
    else:
        visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=rgba, physicsClientId=client)
    position, quat = tf.to_pose(T_world_box)
    body = p.createMultiBody(0.0, collision, visual, position.tolist(), quat.tolist(), physicsClientId=client)
    if gridded:  # a mesh's own colour is ignored
        p.changeVisualShape(body, -1, rgbaColor=rgba, physicsClientId=client)
    return body


def nest_boxes(length: float, width: float) -> list[tuple[tuple, tuple, tuple]]:
    """Boxes (size, centre, quaternion) of a nest: four corner L-brackets of 45 deg lead-in ramps.

    Each bracket leg is a ramp rising from the pocket edge on the bench top to ``NEST_LEAD_IN``
    outside it (hotel_model.corner_ramp_boxes, which the onboard hotel's pockets share), so a plate
    released up to clearance + lead-in off centre slides into the pocket (low-friction bracket
    material). The ramp starts at the bench top, with no vertical wall under it: a wall's top corner
    is a ledge on which a plate's bottom rests 1 deg tilted, held by the bench's friction under its
    other edge (campaigns 6000 and 7000 lost 1 to 1.5 % of transfers so).
    """
    return [
        (size, centre, tuple(tf.matrix_to_quat(tf.rpy_to_matrix(*rpy))))
        for size, centre, rpy in corner_ramp_boxes(
            length, width, NEST_LEAD_IN, foot=NEST_RAMP_FOOT, leg=NEST_LEG_LENGTH
        )
    ]


def _compound_static(client: int, boxes, T_world_body: np.ndarray, rgba) -> int:
    """One static body made of several boxes given as (size, centre[, quaternion]) in the body frame."""
    halves = [[s / 2 for s in box[0]] for box in boxes]
    centres = [list(box[1]) for box in boxes]
    orientations = [list(box[2]) if len(box) > 2 else [0, 0, 0, 1] for box in boxes]
    shapes = [p.GEOM_BOX] * len(boxes)
    collision = p.createCollisionShapeArray(
        shapes,
        halfExtents=halves,
        collisionFramePositions=centres,
        collisionFrameOrientations=orientations,
        physicsClientId=client,
    )
    visual = p.createVisualShapeArray(
        shapes,
        halfExtents=halves,
        visualFramePositions=centres,
        visualFrameOrientations=orientations,
        rgbaColors=[rgba] * len(boxes),
        physicsClientId=client,
    )
    position, quat = tf.to_pose(T_world_body)
    return p.createMultiBody(0.0, collision, visual, position.tolist(), quat.tolist(), physicsClientId=client)


def _build_table(client: int, station: Station, scene: Scene) -> None:
    depth, width, height = station.table_size
    T_world_top = station.T_world_table()
    scene.tables[station.name] = _static_box(
        client,
        (depth, width, height),
        T_world_top @ tf.make_transform((0, 0, -height / 2)),
        [0.75, 0.7, 0.6, 1],
    )
    p.changeDynamics(scene.tables[station.name], -1, lateralFriction=TABLE_FRICTION, physicsClientId=client)


def _build_marker(client: int, station: Station, scene: Scene) -> None:
    """The marker tile, then the thin board standing behind it (the tile hides part of the board)."""
    T_world_marker = station.T_world_marker()
    T_world_tile = T_world_marker @ tf.make_transform((0, 0, 0.0008))
    scene.markers[station.name] = marker_visual(client, station.marker_id, station.marker_size, T_world_tile)
    T_world_board = T_world_marker @ station.T_marker_board()
    scene.marker_stands[station.name] = _static_box(
        client, station.marker_board_size(), T_world_board, [0.95, 0.95, 0.95, 1]
    )


def _build_nests(client: int, station: Station, labware: LabwareType, scene: Scene) -> None:
    pocket = (labware.length + 2 * station.nest_clearance, labware.width + 2 * station.nest_clearance)
    boxes = nest_boxes(pocket[0], pocket[1])
    for nest in station.nests():
        body = _compound_static(client, boxes, station.T_world_site(nest.sub_position), [0.25, 0.25, 0.28, 1])
        p.changeDynamics(body, -1, lateralFriction=NEST_FRICTION, physicsClientId=client)
        scene.nests[nest] = body


def _plate_body(client: int, labware: LabwareType, T_world_bottom: np.ndarray) -> int:
    half = [labware.length / 2, labware.width / 2, labware.height / 2]
    collision = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    visual = p.createVisualShape(
        p.GEOM_BOX, halfExtents=half, rgbaColor=[0.95, 0.55, 0.15, 1], physicsClientId=client
    )
    T_world_centre = T_world_bottom @ tf.make_transform((0, 0, labware.height / 2 + 0.0005))
    position, quat = tf.to_pose(T_world_centre)
    body = p.createMultiBody(
        labware.mass, collision, visual, position.tolist(), quat.tolist(), physicsClientId=client
    )
    p.changeDynamics(
        body,
        -1,
        lateralFriction=PLATE_FRICTION,
        spinningFriction=PLATE_SPINNING_FRICTION,
        rollingFriction=0.0,
        physicsClientId=client,
    )
    return body


def _build_walls(client: int, floor_size: float) -> dict[str, int]:
    """Four thin walls standing on the floor's edge, inside it, as the occupancy map has them."""
    half, inner = floor_size / 2, floor_size / 2 - WALL_THICKNESS / 2
    rgba = [0.6, 0.6, 0.65, 1]
    long_side = (floor_size, WALL_THICKNESS, WALL_HEIGHT)
    across = (WALL_THICKNESS, floor_size, WALL_HEIGHT)
    z = WALL_HEIGHT / 2
    log.debug("edge walls at +-%.2f m", half)
    return {
        "north wall": _static_box(client, long_side, tf.make_transform((0, inner, z)), rgba),
        "south wall": _static_box(client, long_side, tf.make_transform((0, -inner, z)), rgba),
        "east wall": _static_box(client, across, tf.make_transform((inner, 0, z)), rgba),
        "west wall": _static_box(client, across, tf.make_transform((-inner, 0, z)), rgba),
    }


def _floor_body(client: int, size: float, thickness: float = 0.02) -> int:
    """The floor: a static box whose top face is at z = 0."""
    return _static_box(client, (size, size, thickness), tf.make_transform((0, 0, -thickness / 2)), FLOOR_RGBA)


def _obstacle_body(client: int, obstacle: Obstacle) -> int:
    """A static box or upright cylinder standing on the floor."""
    T_world_centre = tf.from_planar(obstacle.x, obstacle.y, obstacle.yaw, obstacle.height / 2)
    rgba = [0.45, 0.5, 0.6, 1]
    if not obstacle.is_cylinder:
        return _static_box(client, (obstacle.length, obstacle.width, obstacle.height), T_world_centre, rgba)
    collision = p.createCollisionShape(
        p.GEOM_CYLINDER, radius=obstacle.radius, height=obstacle.height, physicsClientId=client
    )
    visual = p.createVisualShape(
        p.GEOM_CYLINDER,
        radius=obstacle.radius,
        length=obstacle.height,
        rgbaColor=rgba,
        physicsClientId=client,
    )
    position, quat = tf.to_pose(T_world_centre)
    return p.createMultiBody(0.0, collision, visual, position.tolist(), quat.tolist(), physicsClientId=client)


def plate_bottom_pose(client: int, body: int, labware: LabwareType) -> np.ndarray:
    """T_world of the plate's bottom-centre frame (what a nest site frame should coincide with)."""
    position, quat = p.getBasePositionAndOrientation(body, physicsClientId=client)
    return tf.from_pose(position, quat) @ tf.make_transform((0, 0, -labware.height / 2))


def build_scene(client: int, world: World, T_world_hotel_slots: dict[int, np.ndarray] | None = None) -> Scene:
    """Create the lab and its plates; hotel plates need the slot poses of the placed robot.

    Bodies are created front to back (markers, plates, nests, tables, then dock, obstacles, walls
    and floor) because creation order is draw order in PyBullet's software renderer, which tests
    depth before it shades a pixel: a bench, wall or floor drawn after what stands on or before it
    never shades the hidden pixels. Same images (tests/tiago_sim/physics/test_scene_gridded_boxes.py),
    about an eighth cheaper at a bench (682 -> 602 ms for five frames, before the grids).
    """
    scene = Scene()
    default_type = next(iter(world.labware_types.values()))
    for station in world.stations:
        _build_marker(client, station, scene)
    for plate, holder in world.plates.items():
        labware = world.labware_types[plate.labware_type]
        if isinstance(holder, HotelSlot):
            if T_world_hotel_slots is None:
                raise ValueError(f"plate {plate.labware_id} starts in the hotel but no slot poses were given")
            T_world_bottom = T_world_hotel_slots[holder.index]
        else:
            T_world_bottom = world.station(holder.station).T_world_site(holder.sub_position)
        scene.plates[plate.labware_id] = _plate_body(client, labware, T_world_bottom)
        scene.plate_types[plate.labware_id] = labware
    for station in world.stations:
        _build_nests(client, station, default_type, scene)
    for station in world.stations:
        _build_table(client, station, scene)
    dock = dock_box(world.dock_pose)
    T_world_dock = tf.from_planar(dock.x, dock.y, dock.yaw, DOCK_SIZE[2] / 2)
    scene.dock = _static_box(client, DOCK_SIZE, T_world_dock, [0.2, 0.3, 0.2, 1])
    scene.obstacles = {obstacle.name: _obstacle_body(client, obstacle) for obstacle in world.obstacles}
    scene.walls = _build_walls(client, world.floor_size)
    scene.floor = _floor_body(client, world.floor_size)
    log.debug("floor %.1f m square", world.floor_size)
    return scene
