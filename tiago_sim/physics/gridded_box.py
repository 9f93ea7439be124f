"""A box's visual as a mesh whose faces are cut into small squares: the same pixels, cheaper to render.

Why: PyBullet's software renderer (TinyRenderer) walks every pixel of each triangle's bounding
box. A box's own visual has two triangles per face, so a wall 10 m long or a bench seen from
close by spans the whole image with a handful of triangles, each walked in full: at a bench the
four edge walls cost half of a head-camera frame (60 of 125 ms) though they fill little of it.
Cut into squares of at most GRID_CELL, each triangle's box is about what it covers.
The pixels stay the same (tests/tiago_sim/physics/test_scene_gridded_boxes.py).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import pybullet as p

GRID_CELL = 0.5  # m: the longest side of a face's squares


def _face(
    half: Sequence[float], axis: int, sign: int, cell: float
) -> tuple[list[list[float]], list[list[float]], list[int]]:
    """Vertices, normals and counter-clockwise (seen from outside) triangles of one face."""
    u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3
    if sign < 0:  # keep u x v along the outward normal
        u_axis, v_axis = v_axis, u_axis
    cells_u = max(1, math.ceil(2 * half[u_axis] / cell))
    cells_v = max(1, math.ceil(2 * half[v_axis] / cell))
    normal = [0.0, 0.0, 0.0]
    normal[axis] = float(sign)
    vertices = []
    for j in range(cells_v + 1):
        for i in range(cells_u + 1):
            point = [0.0, 0.0, 0.0]
            point[axis] = sign * half[axis]
            point[u_axis] = -half[u_axis] + 2 * half[u_axis] * i / cells_u
            point[v_axis] = -half[v_axis] + 2 * half[v_axis] * j / cells_v
            vertices.append(point)
    indices = []
    for j in range(cells_v):
        for i in range(cells_u):
            corner = j * (cells_u + 1) + i
            above = corner + cells_u + 1
            indices += [corner, corner + 1, above + 1, corner, above + 1, above]
    return vertices, [normal] * len(vertices), indices


def gridded_box_visual(
    client: int, half_extents: Sequence[float], rgba: Sequence[float], cell: float = GRID_CELL
) -> int:
    """A visual shape looking like a box of ``half_extents``, its faces cut into squares <= ``cell``."""
    vertices: list[list[float]] = []
    normals: list[list[float]] = []
    indices: list[int] = []
    for axis in range(3):
        for sign in (1, -1):
            face_vertices, face_normals, face_indices = _face(half_extents, axis, sign, cell)
            indices += [len(vertices) + index for index in face_indices]
            vertices += face_vertices
            normals += face_normals
    return p.createVisualShape(
        p.GEOM_MESH,
        vertices=vertices,
        indices=indices,
        normals=normals,
        rgbaColor=list(rgba),
        physicsClientId=client,
    )
