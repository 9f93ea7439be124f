"""A small URDF text builder for robots made of primitive shapes (boxes, cylinders, spheres).

Why: robot_model.py describes the robot in numbers; this keeps the XML formatting out of it.
Pure text; safe on any thread.
"""

from __future__ import annotations

import math

import numpy as np


def _fmt(values) -> str:
    return " ".join(f"{float(v):.10g}" for v in values)


def _rpy_aligning_z(direction: np.ndarray) -> tuple[float, float, float]:
    """URDF rpy that turns the z axis onto ``direction`` (for cylinders along a segment)."""
    d = direction / np.linalg.norm(direction)
    pitch = math.acos(max(-1.0, min(1.0, d[2])))
    yaw = math.atan2(d[1], d[0])
    return (0.0, pitch, yaw)


class UrdfWriter:
    """Accumulates links and joints; keeps the geometry helpers in one place."""

    def __init__(self, name: str) -> None:
        self.parts: list[str] = [f'<?xml version="1.0"?>\n<robot name="{name}">']
        self.parts.append(
            '<material name="dark"><color rgba="0.2 0.2 0.22 1"/></material>'
            '<material name="white"><color rgba="0.9 0.9 0.9 1"/></material>'
            '<material name="grey"><color rgba="0.55 0.55 0.58 1"/></material>'
            '<material name="pad"><color rgba="0.1 0.35 0.6 1"/></material>'
        )

    @staticmethod
    def geometry(shape: str, size) -> str:
        if shape == "box":
            return f'<box size="{_fmt(size)}"/>'
        if shape == "cylinder":
            return f'<cylinder radius="{size[0]:.6g}" length="{size[1]:.6g}"/>'
        return f'<sphere radius="{size[0]:.6g}"/>'

    def link(self, name: str, mass: float = 0.0, shapes=(), collide: bool = True) -> None:
        """A link with ``shapes`` = [(shape, size, xyz, rpy, material)] used for visual and collision."""
        body = [f'<link name="{name}">']
        if mass <= 0.0:  # frames: a token mass keeps PyBullet from treating them as static
            mass = 0.001
        if mass > 0.0:
            inertia = max(mass * 0.002, 1e-6)
            body.append(
                f'<inertial><origin xyz="0 0 0"/><mass value="{mass:.6g}"/>'
                f'<inertia ixx="{inertia:.6g}" iyy="{inertia:.6g}" izz="{inertia:.6g}" '
                'ixy="0" ixz="0" iyz="0"/></inertial>'
            )
        for shape, size, xyz, rpy, material in shapes:
            geometry = self.geometry(shape, size)
            origin = f'<origin xyz="{_fmt(xyz)}" rpy="{_fmt(rpy)}"/>'
            body.append(
                f'<visual>{origin}<geometry>{geometry}</geometry><material name="{material}"/></visual>'
            )
            if collide:
                body.append(f"<collision>{origin}<geometry>{geometry}</geometry></collision>")
        body.append("</link>")
        self.parts.append("\n".join(body))  # PyBullet rejects URDF lines over ~10k characters

    def joint(
        self, name: str, kind: str, parent: str, child: str, xyz=(0, 0, 0), rpy=(0, 0, 0), **opts
    ) -> None:
        text = [
            f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{_fmt(xyz)}" rpy="{_fmt(rpy)}"/>'
        ]
        if kind != "fixed":
            text.append(f'<axis xyz="{_fmt(opts.get("axis", (0, 0, 1)))}"/>')
            lower, upper = opts.get("limits", (0.0, 0.0))
            text.append(
                f'<limit lower="{lower:.10g}" upper="{upper:.10g}" '
                f'effort="{opts.get("effort", 10.0):.6g}" velocity="{opts.get("velocity", 1.0):.6g}"/>'
            )
            text.append('<dynamics damping="0.5" friction="0.0"/>')
        text.append("</joint>")
        self.parts.append("".join(text))

    def segment_shapes(self, end_xyz, radius: float, material: str = "white"):
        """A cylinder from the link origin to ``end_xyz`` (the next joint), plus a joint sphere."""
        end = np.asarray(end_xyz, dtype=float)
        length = float(np.linalg.norm(end))
        shapes = [("sphere", (radius,), (0, 0, 0), (0, 0, 0), "dark")]
        if length > 1e-6:
            shapes.append(("cylinder", (radius, length), tuple(end / 2), _rpy_aligning_z(end), material))
        return shapes

    def text(self) -> str:
        return "\n".join(self.parts + ["</robot>"])
