"""Rigid transforms as 4x4 homogeneous matrices, the one representation used across tiago_sim.

Naming: ``T_a_b`` is the pose of frame ``b`` expressed in frame ``a`` (maps points from b to a),
so ``T_a_c = T_a_b @ T_b_c``. Quaternions are (x, y, z, w), as PyBullet and ROS order them.
Planar poses on the floor (x, y, yaw) have their own small helpers: the base and localisation
compose them every step, where 4x4 matrices would cost more than the arithmetic.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

Matrix4 = np.ndarray
Planar = tuple[float, float, float]  # x, y (m), yaw (rad) on the floor


def quat_to_matrix(quat_xyzw: Sequence[float]) -> np.ndarray:
    """3x3 rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = (float(v) for v in quat_xyzw)
    n = x * x + y * y + z * z + w * w
    if n < 1e-12:
        raise ValueError("zero quaternion")
    s = 2.0 / n
    return np.array(
        [
            [1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
            [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
            [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)],
        ]
    )


def matrix_to_quat(rotation: np.ndarray) -> np.ndarray:
    """Unit quaternion (x, y, z, w) of a 3x3 rotation matrix, with w >= 0."""
    m = np.asarray(rotation, dtype=float)
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        s = 2.0 * np.sqrt(trace + 1.0)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s]
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s]
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s, (m[1, 0] - m[0, 1]) / s]
    quat = np.array(q)
    quat /= np.linalg.norm(quat)
    return -quat if quat[3] < 0 else quat


def rpy_to_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """3x3 rotation of fixed-axis roll, pitch, yaw (URDF convention: R = Rz(yaw) Ry(pitch) Rx(roll))."""
    cr, sr = np.cos(roll), np.sin(roll)
    cp, sp = np.cos(pitch), np.sin(pitch)
    cy, sy = np.cos(yaw), np.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def make_transform(
    translation: Sequence[float] = (0.0, 0.0, 0.0), rotation: np.ndarray | None = None
) -> Matrix4:
    """4x4 transform from a translation and an optional 3x3 rotation."""
    transform = np.eye(4)
    transform[:3, 3] = np.asarray(translation, dtype=float)
    if rotation is not None:
        transform[:3, :3] = rotation
    return transform


def from_pose(position: Sequence[float], quat_xyzw: Sequence[float]) -> Matrix4:
    """4x4 transform from a position and a quaternion (x, y, z, w)."""
    return make_transform(position, quat_to_matrix(quat_xyzw))


def from_xyz_rpy(xyz: Sequence[float], rpy: Sequence[float] = (0.0, 0.0, 0.0)) -> Matrix4:
    """4x4 transform from a translation and URDF-style roll, pitch, yaw."""
    return make_transform(xyz, rpy_to_matrix(*rpy))


def from_planar(x: float, y: float, yaw: float, z: float = 0.0) -> Matrix4:
    """4x4 transform of a pose on the floor (x, y, heading yaw) lifted to height z."""
    return from_xyz_rpy((x, y, z), (0.0, 0.0, yaw))


def to_pose(transform: Matrix4) -> tuple[np.ndarray, np.ndarray]:
    """(position, quaternion xyzw) of a 4x4 transform."""
    return transform[:3, 3].copy(), matrix_to_quat(transform[:3, :3])


def invert(transform: Matrix4) -> Matrix4:
    """Inverse of a rigid 4x4 transform."""
    inverse = np.eye(4)
    rotation_t = transform[:3, :3].T
    inverse[:3, :3] = rotation_t
    inverse[:3, 3] = -rotation_t @ transform[:3, 3]
    return inverse


def yaw_of(transform: Matrix4) -> float:
    """Heading (rotation about world z) of a 4x4 transform's x axis."""
    return float(np.arctan2(transform[1, 0], transform[0, 0]))


def levelled(transform: Matrix4) -> Matrix4:
    """The same origin and heading with z straight up: roll and pitch dropped (a frame on a level bench)."""
    x, y, z = (float(v) for v in transform[:3, 3])
    return from_planar(x, y, yaw_of(transform), z)


def wrap_angle(angle: float) -> float:
    """Angle wrapped to (-pi, pi]."""
    return float(np.arctan2(np.sin(angle), np.cos(angle)))


def rotation_angle(rotation_a: np.ndarray, rotation_b: np.ndarray) -> float:
    """Angle in radians of the rotation that takes rotation_a to rotation_b."""
    relative = np.asarray(rotation_a).T @ np.asarray(rotation_b)
    cos_angle = np.clip((np.trace(relative) - 1.0) / 2.0, -1.0, 1.0)
    return float(np.arccos(cos_angle))


def compose_planar(a: Planar, b: Planar) -> Planar:
    """Planar pose ``b`` given in the frame of planar pose ``a``, expressed in ``a``'s parent frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], math.remainder(a[2] + b[2], math.tau))


def invert_planar(a: Planar) -> Planar:
    """The planar transform that undoes ``a``: compose_planar(a, invert_planar(a)) is the identity."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], math.remainder(-a[2], math.tau))
