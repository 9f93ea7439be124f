"""Obstacles not on the map, from scan points alone (no physics): which points are unexplained,
which of them block the corridor ahead, and which marks a fresh scan sees through."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lab_description.world import DEFAULT_WORLD, load_world
from tiago_sim.navigation.blockage import (
    CORRIDOR_HALF_WIDTH_M,
    LOOKAHEAD_M,
    UnmappedObstacles,
    still_there,
    to_map_frame,
)
from tiago_sim.navigation.occupancy_map import build_map

PATH = [(-1.0, -1.0), (1.0, -1.0)]  # open floor in the default lab, along +x


@pytest.fixture(scope="module")
def obstacles() -> UnmappedObstacles:
    return UnmappedObstacles(build_map(load_world(DEFAULT_WORLD)))


def face(x: float, y_from: float, y_to: float, count: int = 10) -> np.ndarray:
    """Points of a box face across the path (the side the laser sees)."""
    return np.array([(x, y) for y in np.linspace(y_from, y_to, count)])


def test_a_face_across_the_path_blocks_it_at_its_distance_along_the_path(
    obstacles: UnmappedObstacles,
) -> None:
    blockage = obstacles.blocking(face(0.0, -1.2, -0.8), PATH)
    assert blockage is not None
    assert blockage.ahead_m == pytest.approx(1.0, abs=1e-9)  # from the base centre at x = -1
    assert "0.73 m ahead of the base" in blockage.text()  # minus the base's 0.265 m radius


def test_points_beside_the_corridor_behind_the_base_or_beyond_the_lookahead_do_not(
    obstacles: UnmappedObstacles,
) -> None:
    beside = face(0.0, -1.0 + CORRIDOR_HALF_WIDTH_M + 0.02, -0.3)
    behind = face(-1.3, -1.2, -0.8)
    beyond = face(-1.0 + LOOKAHEAD_M + 0.1, -1.2, -0.8)
    for points in (beside, behind, beyond):
        assert obstacles.blocking(points, PATH) is None


def test_two_stray_beams_are_noise_and_the_static_map_explains_its_own_benches(
    obstacles: UnmappedObstacles,
) -> None:
    assert obstacles.blocking(face(0.0, -1.05, -0.95, count=2), PATH) is None
    bench_a_front = face(1.65, -0.4, 0.4)  # station_a's table: centre x 2.0, depth 0.7
    assert not len(obstacles.unexplained(bench_a_front))


def test_a_mark_a_fresh_beam_passes_beyond_is_forgotten_one_out_of_view_stays() -> None:
    seen = np.array([[1.0, 0.0], [0.0, 1.0]])
    origin = (0.0, 0.0)
    beam_rad = math.radians(1.0 / 3.0)
    through = np.array([[3.0, 0.0]])  # the beam along +x now ends 3 m away
    assert still_there(seen, through, origin, beam_rad).tolist() == [[0.0, 1.0]]
    short = np.array([[1.01, 0.0]])  # the beam still ends at the mark
    assert len(still_there(seen, short, origin, beam_rad)) == 2


def test_scan_points_go_into_the_map_frame_at_the_pose() -> None:
    points = to_map_frame(np.array([[1.0, 0.0]]), (2.0, 3.0, math.pi / 2))
    assert points[0].tolist() == pytest.approx([2.0, 4.0])
