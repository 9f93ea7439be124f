"""Floor-plan gaps between where the robot stands or drives and what stands on the floor.

Why a module of its own: the loader's checks (`serviceability`), the layout generator and the tests
measure the same gaps, to a bench's outline and to the dock's; one function each keeps their numbers
equal. Pure numpy; any thread.
"""

from __future__ import annotations

import math

import numpy as np

from lab_description.world_obstacles import dock_box


def rectangle_distances(
    centre: tuple[float, float, float], depth: float, width: float, xs: np.ndarray, ys: np.ndarray
) -> np.ndarray:
    """Distance (m) from each floor point to a rectangle (`centre` x, y, yaw; `depth` along the yaw);
    negative inside it, as deep as the nearest edge."""
    x, y, yaw = centre
    c, s = math.cos(yaw), math.sin(yaw)
    dx, dy = xs - x, ys - y
    along = np.abs(c * dx + s * dy) - depth / 2
    across = np.abs(-s * dx + c * dy) - width / 2
    outside = np.hypot(np.maximum(along, 0.0), np.maximum(across, 0.0))
    return np.where(outside > 0, outside, np.maximum(along, across))


def bench_distance(station, x: float, y: float) -> float:  # noqa: ANN001
    """Distance (m) from floor point (x, y) to the station's bench outline; negative inside it."""
    return float(bench_distances(station, np.asarray(x, dtype=float), np.asarray(y, dtype=float)))


def bench_distances(station, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:  # noqa: ANN001
    """`bench_distance` for many floor points at once (a drive sampled every few centimetres)."""
    pose = station.table_pose
    return rectangle_distances((pose.x, pose.y, pose.yaw), *station.table_size[:2], xs, ys)


def dock_distances(dock_pose, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:  # noqa: ANN001 - Pose2D
    """Distance (m) from each floor point to the charging dock's outline (`world_obstacles.dock_box`)."""
    dock = dock_box(dock_pose)
    return rectangle_distances((dock.x, dock.y, dock.yaw), dock.length, dock.width, xs, ys)


def obstacle_distances(obstacle, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:  # noqa: ANN001 - Obstacle
    """Distance (m) from each floor point to a free-standing obstacle's outline (box or cylinder)."""
    if obstacle.is_cylinder:
        return np.hypot(xs - obstacle.x, ys - obstacle.y) - obstacle.radius
    centre = (obstacle.x, obstacle.y, obstacle.yaw)
    return rectangle_distances(centre, obstacle.length, obstacle.width, xs, ys)


def drive_points(start, end, count: int) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001 - Pose2D
    """`count` + 1 floor points evenly along the straight drive from `start` to `end`, both ends in."""
    k = np.arange(count + 1, dtype=float) / count
    return start.x + (end.x - start.x) * k, start.y + (end.y - start.y) * k


def closest(gaps: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> tuple[float, float, float]:
    """The least of the gaps along sampled points, and where it is: (gap, x, y)."""
    nearest = int(np.argmin(gaps))
    return float(gaps[nearest]), float(xs[nearest]), float(ys[nearest])
