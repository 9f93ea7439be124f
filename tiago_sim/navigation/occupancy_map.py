"""The lab as an occupancy grid, built from the world file.

Why from the world file: it is the map a lab integrator already wrote (benches, the floor's
walls); a real TIAGo++ gets its map from a mapping run, which the simulation skips. Planning uses
the map inflated by the robot's footprint; localisation matches laser scans against the plain map.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from lab_description.world import MARKER_BOARD_SCALE, World
from lab_description.world_obstacles import DOCK_SIZE, dock_box

DEFAULT_RESOLUTION = 0.05  # m per cell (the ROS 2 navigation stack's usual resolution)
WALL_THICKNESS = 0.10  # m: the floor's edge is a wall this thick, inside the floor
BOARD_BAND = 0.04  # m: a marker board (1 cm thick, 6 mm behind the marker) as a strip on the map


@dataclass(frozen=True)
class Footprint:
    """An obstacle's outline on the floor: a rectangle (centre, heading, length x width) or a disc."""

    x: float
    y: float
    yaw: float = 0.0
    length: float = 0.0  # along the heading (m)
    width: float = 0.0
    radius: float = 0.0  # > 0: a disc; the rectangle fields are ignored


@dataclass(frozen=True)
class OccupancyMap:
    """Cells of ``resolution`` m; ``occupied[row, col]`` with row along y, col along x from ``origin``
    (the world position of cell (0, 0)'s lower-left corner), as nav_msgs/OccupancyGrid stores them."""

    resolution: float
    origin: tuple[float, float]
    occupied: np.ndarray  # bool, shape (rows, cols)

    @property
    def shape(self) -> tuple[int, int]:
        return self.occupied.shape  # type: ignore[return-value]

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        """(row, col) of the cell containing world point (x, y); may lie outside the grid."""
        return (
            math.floor((y - self.origin[1]) / self.resolution),
            math.floor((x - self.origin[0]) / self.resolution),
        )

    def centre_of(self, row: int, col: int) -> tuple[float, float]:
        """World (x, y) of a cell's centre."""
        return (
            self.origin[0] + (col + 0.5) * self.resolution,
            self.origin[1] + (row + 0.5) * self.resolution,
        )

    def inside(self, row: int, col: int) -> bool:
        rows, cols = self.shape
        return 0 <= row < rows and 0 <= col < cols

    def is_free(self, x: float, y: float) -> bool:
        """Free cell at (x, y); outside the grid counts as occupied."""
        row, col = self.cell_of(x, y)
        return self.inside(row, col) and not bool(self.occupied[row, col])

    def clearance_m(self) -> np.ndarray:
        """Per cell, the distance (m) from its centre to the nearest occupied cell's centre."""
        free = (~self.occupied).astype(np.uint8)
        return cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE) * self.resolution

    def inflated(self, radius_m: float) -> OccupancyMap:
        """Occupied wherever a disc of ``radius_m`` centred on the cell would touch an obstacle."""
        blocked = self.clearance_m() < radius_m
        return OccupancyMap(self.resolution, self.origin, blocked | self.occupied)

    def with_footprints(self, footprints: list[Footprint]) -> OccupancyMap:
        """A copy with these outlines marked occupied (e.g. obstacles seen but not on the map)."""
        grid = self.occupied.astype(np.uint8)
        for footprint in footprints:
            _draw(grid, self, footprint)
        return OccupancyMap(self.resolution, self.origin, grid.astype(bool))


def station_footprints(world: World, above_m: float = 0.0) -> list[Footprint]:
    """Every bench's outline; with `above_m`, the benches whose top is higher, and of a lower bench
    the marker's board where that reaches higher (a thin strip along the marker's x axis)."""
    footprints = []
    for s in world.stations:
        if s.table_size[2] > above_m:
            footprints.append(
                Footprint(s.table_pose.x, s.table_pose.y, s.table_pose.yaw, s.table_size[0], s.table_size[1])
            )
        elif s.top_height() > above_m:
            T_world_marker = s.T_world_marker()
            x, y = T_world_marker[:2, 3]
            yaw = math.atan2(T_world_marker[1, 0], T_world_marker[0, 0])
            footprints.append(
                Footprint(float(x), float(y), yaw, s.marker_size * MARKER_BOARD_SCALE, BOARD_BAND)
            )
    return footprints


def obstacle_footprints(world: World, above_m: float = 0.0) -> list[Footprint]:
    """Every free-standing obstacle's outline (boxes and cylinders of the world file) taller than
    `above_m`."""
    return [
        Footprint(o.x, o.y, o.yaw, o.length, o.width, o.radius) for o in world.obstacles if o.height > above_m
    ]


def dock_footprint(world: World) -> Footprint:
    """The charging dock's outline: behind the docked robot (physics.scene builds it there)."""
    dock = dock_box(world.dock_pose)
    return Footprint(dock.x, dock.y, dock.yaw, dock.length, dock.width)


def build_map(world: World, resolution: float = DEFAULT_RESOLUTION, above_m: float = 0.0) -> OccupancyMap:
    """The static map: the floor's edge walls, the dock, every bench and every free-standing obstacle;
    with `above_m`, only what reaches higher than that (the walls always: what the folded arms meet)."""
    half = world.floor_size / 2
    cells = math.ceil(world.floor_size / resolution)
    empty = OccupancyMap(resolution, (-half, -half), np.zeros((cells, cells), dtype=bool))
    wall_cells = max(1, math.ceil(WALL_THICKNESS / resolution))
    grid = empty.occupied.copy()
    grid[:wall_cells, :] = grid[-wall_cells:, :] = True
    grid[:, :wall_cells] = grid[:, -wall_cells:] = True
    walled = OccupancyMap(resolution, empty.origin, grid)
    dock = [dock_footprint(world)] if DOCK_SIZE[2] > above_m else []
    return walled.with_footprints(
        [*dock, *station_footprints(world, above_m), *obstacle_footprints(world, above_m)]
    )


def _draw(grid: np.ndarray, grid_map: OccupancyMap, footprint: Footprint) -> None:
    """Mark the cells an outline covers (any overlap counts) in a uint8 grid."""
    scale = 1.0 / grid_map.resolution

    def to_pixel(x: float, y: float) -> tuple[float, float]:
        return ((x - grid_map.origin[0]) * scale - 0.5, (y - grid_map.origin[1]) * scale - 0.5)

    if footprint.radius > 0.0:
        cx, cy = to_pixel(footprint.x, footprint.y)
        shift = 4  # cv2 draws with fixed-point sub-pixel coordinates
        cv2.circle(
            grid,
            (round(cx * (1 << shift)), round(cy * (1 << shift))),
            round((footprint.radius * scale + 0.5) * (1 << shift)),
            1,
            thickness=-1,
            shift=shift,
        )
        return
    c, s = math.cos(footprint.yaw), math.sin(footprint.yaw)
    hl, hw = footprint.length / 2, footprint.width / 2
    corners = [
        to_pixel(footprint.x + c * dx - s * dy, footprint.y + s * dx + c * dy)
        for dx, dy in ((hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw))
    ]
    polygon = np.array([[round(px), round(py)] for px, py in corners], dtype=np.int32)
    cv2.fillConvexPoly(grid, polygon, 1)
