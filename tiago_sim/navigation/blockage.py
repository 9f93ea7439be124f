"""Things that are not on the map: laser points the static map does not explain, and whether any
of them lies in the corridor the robot is about to drive.

Why this rule: the map is what the robot believes of the lab; a beam ending more than
``EXPLAINED_M`` from every mapped surface hit something the map does not know (the laser's 2 cm
noise, localisation's centimetre and a bench displaced by a few centimetres all stay well inside
it). Such a point matters only if the base would run into it: within ``CORRIDOR_HALF_WIDTH_M``
of the path still to drive (the base's radius plus the 10 cm it must stay short) and within
``LOOKAHEAD_M`` along it, which covers TIAGo's stopping distance from top speed (1.0 m at
0.5 m/s^2), the time between two looks and the base's radius. A single beam is noise;
``MIN_POINTS`` beams make an obstacle. Pure (numpy); any thread. Units: metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tiago_description.robot_model import BASE_RADIUS
from tiago_sim.navigation.occupancy_map import Footprint, OccupancyMap

EXPLAINED_M = 0.15
"""A beam ending closer than this to a mapped obstacle hit the map (the localisation map's own
disturbance of a few centimetres and 2 cm range noise included)."""
STOP_SHORT_M = 0.10
"""The base stops at least this far from an obstacle it sees."""
CORRIDOR_HALF_WIDTH_M = BASE_RADIUS + STOP_SHORT_M
LOOKAHEAD_M = 2.5
"""Along the path from the base centre: stopping from 1 m/s takes 1.0 m, a look every 0.1 s adds
0.1 m, the base's front is 0.265 m ahead of its centre, plus the 0.1 m margin: 1.47 m; kept wider."""
MIN_POINTS = 3
MARK_RANGE_M = 10.0
"""Unexplained points this close to the robot go onto its local map: the laser's whole range, so a
wall across the lab is marked whole at the first look (a heading error of 3 mrad moves a point at
10 m by 3 cm, inside EXPLAINED_M)."""
SEEN_THROUGH_M = 0.15
"""A marked point is gone when a fresh beam along its bearing reaches this much farther."""
MARK_RADIUS_M = 0.05
"""Each marked point is a disc this large on the local map (one map cell)."""


@dataclass(frozen=True)
class Blockage:
    """Obstacle points in the corridor ahead: ``points`` (N, 2) in the map frame, ``ahead_m`` the
    path length from the base centre to the nearest of them, ``near`` that point."""

    points: np.ndarray
    ahead_m: float
    near: tuple[float, float]

    def text(self) -> str:
        return (
            f"an obstacle not on the map at ({self.near[0]:.2f}, {self.near[1]:.2f}), "
            f"{self.ahead_m - BASE_RADIUS:.2f} m ahead of the base"
        )


def to_map_frame(points_base: np.ndarray, pose: tuple[float, float, float]) -> np.ndarray:
    """Scan endpoints (N, 2) from base_footprint into the map frame at the base pose (x, y, yaw)."""
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    rotation = np.array([[c, -s], [s, c]])
    return points_base @ rotation.T + np.array([x, y])


class UnmappedObstacles:
    """Tells scan points the static map explains from those it does not (build once per map)."""

    def __init__(self, static_map: OccupancyMap) -> None:
        self.static_map = static_map
        self.clearance = static_map.clearance_m()

    def unexplained(self, points: np.ndarray) -> np.ndarray:
        """The points (map frame) farther than EXPLAINED_M from every mapped obstacle."""
        if not len(points):
            return points
        grid = self.static_map
        cols = np.floor((points[:, 0] - grid.origin[0]) / grid.resolution).astype(int)
        rows = np.floor((points[:, 1] - grid.origin[1]) / grid.resolution).astype(int)
        inside = (rows >= 0) & (rows < grid.shape[0]) & (cols >= 0) & (cols < grid.shape[1])
        clearance = np.zeros(len(points))
        clearance[inside] = self.clearance[rows[inside], cols[inside]]
        return points[inside & (clearance > EXPLAINED_M)]

    def near_robot(self, points: np.ndarray, robot_xy: tuple[float, float]) -> np.ndarray:
        """The unexplained points within MARK_RANGE_M of the robot: what goes onto its local map."""
        unexplained = self.unexplained(points)
        return unexplained[np.hypot(*(unexplained - np.array(robot_xy)).T) <= MARK_RANGE_M]

    def blocking(self, points: np.ndarray, path: list[tuple[float, float]]) -> Blockage | None:
        """The unexplained points in the corridor along `path` (from the base centre on, cut at
        LOOKAHEAD_M), if at least MIN_POINTS of them."""
        unexplained = self.unexplained(points)
        if len(unexplained) < MIN_POINTS or len(path) < 2:
            return None
        best_lateral = np.full(len(unexplained), np.inf)
        best_along = np.full(len(unexplained), np.inf)
        travelled = 0.0
        for a, b in zip(path, path[1:], strict=False):
            if travelled >= LOOKAHEAD_M:
                break
            start, end = np.array(a), np.array(b)
            length = float(np.linalg.norm(end - start))
            if length < 1e-6:
                continue
            direction = (end - start) / length
            reach = min(length, LOOKAHEAD_M - travelled)
            raw = (unexplained - start) @ direction
            along = np.clip(raw, 0.0, reach)
            lateral = np.linalg.norm(unexplained - (start + along[:, None] * direction), axis=1)
            if travelled == 0.0:
                lateral[raw < 0.0] = np.inf  # behind the base: not where it drives
            closer = lateral < best_lateral
            best_lateral[closer], best_along[closer] = lateral[closer], travelled + along[closer]
            travelled += length
        inside = best_lateral <= CORRIDOR_HALF_WIDTH_M
        if int(inside.sum()) < MIN_POINTS:
            return None
        nearest = int(np.argmin(np.where(inside, best_along, np.inf)))
        near = (float(unexplained[nearest, 0]), float(unexplained[nearest, 1]))
        return Blockage(unexplained[inside], float(best_along[nearest]), near)


def still_there(
    seen: np.ndarray, points: np.ndarray, origin: tuple[float, float], beam_rad: float
) -> np.ndarray:
    """The marked points `seen` a fresh scan does not see through: a point stays unless the scan
    endpoint (`points`, map frame, cast from the laser at `origin`) nearest its bearing, within
    `beam_rad`, lies SEEN_THROUGH_M beyond it. Points outside the scan's view stay."""
    if not len(seen) or not len(points):
        return seen
    beams = points - np.array(origin)
    marked = seen - np.array(origin)
    beam_bearing = np.arctan2(beams[:, 1], beams[:, 0])
    order = np.argsort(beam_bearing)
    sorted_bearing, beam_range = beam_bearing[order], np.hypot(*beams[order].T)
    bearing = np.arctan2(marked[:, 1], marked[:, 0])
    index = np.clip(np.searchsorted(sorted_bearing, bearing), 1, len(order) - 1)
    left_closer = np.abs(sorted_bearing[index - 1] - bearing) < np.abs(sorted_bearing[index] - bearing)
    nearer = np.where(left_closer, index - 1, index)
    in_view = np.abs(sorted_bearing[nearer] - bearing) <= beam_rad
    through = in_view & (beam_range[nearer] > np.hypot(*marked.T) + SEEN_THROUGH_M)
    return seen[~through]


def marks(points: np.ndarray) -> list[Footprint]:
    """Seen obstacle points as discs for ``OccupancyMap.with_footprints`` (the robot's local map)."""
    return [Footprint(float(x), float(y), radius=MARK_RADIUS_M) for x, y in points]
