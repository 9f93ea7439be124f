"""The map as a signed distance field: how far a laser endpoint lies from the nearest mapped surface.

Why signed and why from cell centres: a scan matcher pulls every endpoint onto a surface, so it
needs the distance and its gradient on both sides of a surface. ``OccupancyMap.clearance_m`` is
zero everywhere inside an obstacle (no gradient there, and points that land inside pull nowhere);
here the occupied side counts negative, and the zero level runs through the centres of the
outermost occupied cells, where the rasterised outline puts the surface (within half a cell: the
localiser builds its map at 1 cm, so within 5 mm). Values and gradients are read with bilinear
interpolation. Pure numpy/OpenCV; built once per map.
"""

from __future__ import annotations

import cv2
import numpy as np

from tiago_sim.navigation.occupancy_map import OccupancyMap

OUTSIDE_M = 10.0  # value off the grid: no surface known there (an endpoint there is an outlier)


class LikelihoodField:
    """Signed distance (m) to the nearest mapped surface, positive in free space."""

    def __init__(self, grid_map: OccupancyMap) -> None:
        self.resolution = grid_map.resolution
        self.origin = np.array(grid_map.origin, dtype=float)
        occupied = grid_map.occupied.astype(np.uint8)
        to_occupied = cv2.distanceTransform(1 - occupied, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
        to_free = cv2.distanceTransform(occupied, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
        signed = np.where(occupied > 0, 1.0 - to_free, to_occupied) * self.resolution
        self.distance = signed.astype(np.float32)  # [row (y), col (x)]
        gradient_y, gradient_x = np.gradient(self.distance, self.resolution)
        self.gradient_x = gradient_x.astype(np.float32)
        self.gradient_y = gradient_y.astype(np.float32)

    def sample(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Distances (N,) and gradients (N, 2) at world points (N, 2); OUTSIDE_M off the grid."""
        rows, cols = self.distance.shape
        # continuous cell coordinates with cell centres at integers
        u = (points[:, 0] - self.origin[0]) / self.resolution - 0.5
        v = (points[:, 1] - self.origin[1]) / self.resolution - 0.5
        inside = (u >= 0) & (v >= 0) & (u < cols - 1) & (v < rows - 1)
        distances = np.full(len(points), OUTSIDE_M)
        gradients = np.zeros((len(points), 2))
        if not inside.any():
            return distances, gradients
        u, v = u[inside], v[inside]
        c0, r0 = np.floor(u).astype(int), np.floor(v).astype(int)
        fu, fv = u - c0, v - r0
        weights = ((1 - fu) * (1 - fv), fu * (1 - fv), (1 - fu) * fv, fu * fv)
        corners = ((r0, c0), (r0, c0 + 1), (r0 + 1, c0), (r0 + 1, c0 + 1))

        def interpolate(grid: np.ndarray) -> np.ndarray:
            return sum(w * grid[r, c] for w, (r, c) in zip(weights, corners, strict=True))

        distances[inside] = interpolate(self.distance)
        gradients[inside, 0] = interpolate(self.gradient_x)
        gradients[inside, 1] = interpolate(self.gradient_y)
        return distances, gradients
