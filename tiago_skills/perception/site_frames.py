"""Hand-over site frames derived from an observed marker, as the reference implementation does.

A station carries one ArUco marker (m) and a plate nest, the site (s). The station description
fixes the site in the marker frame (``site_in_marker``); the robot measures the marker in its
base frame. The site approach (ss) is the same pose moved back along the site's own +z (away
from the nest, "above" it for a nest whose z points up), from where the gripper descends
straight onto the site.

Pure math on 4x4 transforms (tiago_description.transforms convention); safe on any thread.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tiago_description.transforms import make_transform


@dataclass(frozen=True)
class SiteFrames:
    """Site (s) and site approach (ss) poses in the robot base frame."""

    T_base_site: np.ndarray
    T_base_site_approach: np.ndarray


def approach_in_site(approach_offset_m: float | Sequence[float]) -> np.ndarray:
    """4x4 approach pose in the site frame: a height along site +z, or an (x, y, z) offset."""
    if np.isscalar(approach_offset_m):
        offset = np.array([0.0, 0.0, float(approach_offset_m)])
    else:
        offset = np.asarray(approach_offset_m, dtype=float)
        if offset.shape != (3,):
            raise ValueError(f"approach offset must be a number or (x, y, z), got {approach_offset_m!r}")
    return make_transform(offset)


def site_frames(
    T_base_marker: np.ndarray,
    site_in_marker: np.ndarray,
    approach_offset_m: float | Sequence[float],
) -> SiteFrames:
    """Site and site-approach poses in the base frame from the observed marker pose."""
    T_base_site = np.asarray(T_base_marker, dtype=float) @ np.asarray(site_in_marker, dtype=float)
    return SiteFrames(
        T_base_site=T_base_site,
        T_base_site_approach=T_base_site @ approach_in_site(approach_offset_m),
    )


def levelled(T_base_frame: np.ndarray) -> np.ndarray:
    """The same pose with its z axis turned onto the base's +z, keeping its heading.

    A marker seen with a fraction of a degree of tilt would tilt the site by as much; for a nest
    known to be level this removes that error. The heading is taken from the frame's x axis
    projected onto the floor (its y axis if x points nearly straight up or down).
    """
    transform = np.asarray(T_base_frame, dtype=float)
    heading = transform[:3, 0].copy()
    heading[2] = 0.0
    if np.linalg.norm(heading) < 1e-6:
        y_axis = transform[:3, 1].copy()
        y_axis[2] = 0.0
        heading = np.array([y_axis[1], -y_axis[0], 0.0])
    x_axis = heading / np.linalg.norm(heading)
    z_axis = np.array([0.0, 0.0, 1.0])
    rotation = np.column_stack([x_axis, np.cross(z_axis, x_axis), z_axis])
    return make_transform(transform[:3, 3], rotation)


def upright_marker(T_base_marker: np.ndarray, T_table_marker: np.ndarray) -> np.ndarray:
    """The observed marker pose with its tilt taken from the station's level bench, not from the image.

    Keeps the observed position and the bench's observed heading; the marker's roll and pitch about
    the floor are the world file's (``T_table_marker`` on a level table top). Why: a nest lies 0.1 to
    0.15 m from its marker, so the marker's orientation error moves the nest by that lever. Position
    is what a single marker measures best; its out-of-plane tilt and its in-plane turn are what it
    measures worst, and the in-plane turn is partly a marker glued askew, which the nests do not
    share. Seen tilted by 1.1 deg, the marker put a nest 7.5 mm too low (a finger pad pressed on the
    bench top); upright, 1.9 mm.
    """
    T_base_table = levelled(np.asarray(T_base_marker, dtype=float) @ np.linalg.inv(T_table_marker))
    upright = np.asarray(T_base_marker, dtype=float).copy()
    upright[:3, :3] = T_base_table[:3, :3] @ np.asarray(T_table_marker, dtype=float)[:3, :3]
    return upright


def at_height(T_base_frame: np.ndarray, height_m: float) -> np.ndarray:
    """The same pose at ``height_m`` above the floor the base stands on (base_footprint's z = 0).

    Why: a nest's height is the bench's, which the world file gives and no bench shift changes, while
    the height a marker sighting gives carries the head camera's calibration (its tilt over the 0.6 to
    0.9 m to the marker) and the marker's own mounting on its stand. Both reach several millimetres:
    a marker seen 3.6 mm high and glued 2.7 mm up its stand had the nest believed 6.3 mm high, and the
    finger pads closed over the plate's top ("nothing between the fingers"). Position along the floor
    still comes from the marker: benches move on the floor.
    """
    moved = np.asarray(T_base_frame, dtype=float).copy()
    moved[2, 3] = float(height_m)
    return moved


def nest_in_base(
    T_base_marker_seen: np.ndarray, T_table_marker: np.ndarray, T_marker_site: np.ndarray, height_m: float
) -> np.ndarray:
    """A nest frame (site or approach) in base_footprint from a marker sighting: level, its heading and
    floor position from the sighting (``upright_marker``), its height from the bench (``at_height``)."""
    T_base_marker = upright_marker(T_base_marker_seen, T_table_marker)
    return at_height(levelled(T_base_marker @ np.asarray(T_marker_site, dtype=float)), height_m)
