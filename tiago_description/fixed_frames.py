"""The robot model's fixed frames: each fixed joint's parent, child and transform.

Why: on a TIAGo++, robot_state_publisher sends the fixed joints of the robot's URDF on
`/tf_static` (the laser's and the camera's mounts, the grasping frames, the base's footprint), so
software reads where a sensor sits from the robot instead of compiling it in. The simulator sends
ours the same way; the ROS adapter reads them back (a sensor's mount on a real robot is its
calibrated one). Plain data from the URDF text: no ROS import here.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from tiago_description import transforms as tf


@dataclass(frozen=True)
class FixedFrame:
    """A child frame fixed to its parent: `transform` maps child coordinates into the parent's."""

    parent: str
    child: str
    transform: np.ndarray


def fixed_frames(urdf_text: str) -> tuple[FixedFrame, ...]:
    """Every fixed joint of the URDF, in the file's order."""
    frames = []
    for joint in ET.fromstring(urdf_text).iter("joint"):
        if joint.get("type") != "fixed":
            continue
        origin = joint.find("origin")
        xyz = _floats(origin.get("xyz") if origin is not None else None)
        rpy = _floats(origin.get("rpy") if origin is not None else None)
        parent, child = joint.find("parent"), joint.find("child")
        assert parent is not None and child is not None, f"joint {joint.get('name')} lacks a link"
        frames.append(FixedFrame(parent.get("link", ""), child.get("link", ""), tf.from_xyz_rpy(xyz, rpy)))
    return tuple(frames)


def _floats(text: str | None) -> tuple[float, float, float]:
    values = [float(part) for part in (text or "0 0 0").split()]
    return values[0], values[1], values[2]


def chain(frames: dict[str, FixedFrame], parent: str, child: str) -> np.ndarray | None:
    """`child` in `parent` through fixed frames (`frames` by child name), None if they do not join."""
    transform = np.eye(4)
    frame = child
    for _ in range(len(frames) + 1):
        if frame == parent:
            return transform
        link = frames.get(frame)
        if link is None:
            return None
        transform = link.transform @ transform
        frame = link.parent
    return None
