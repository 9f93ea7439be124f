"""Marker assets and head-camera rendering, checked on real PyBullet renders with real OpenCV."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np
import pybullet as p
import pytest

from tiago_description.transforms import invert, make_transform
from tiago_sim.physics.camera import CameraIntrinsics, optical_frame_looking_at, render_rgbd
from tiago_sim.physics.marker_asset import (
    MIRROR_AMBIGUOUS_IDS,
    marker_asset_paths,
    marker_texture,
    marker_visual,
)

INTRINSICS = CameraIntrinsics()
# Marker facing +x: marker x = world +y, marker y = world +z (up), marker z = world +x.
MARKER_FACING_X = np.column_stack([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])


@pytest.fixture
def client() -> Iterator[int]:
    client_id = p.connect(p.DIRECT)
    yield client_id
    p.disconnect(client_id)


def project(T_optical_world: np.ndarray, points_world: np.ndarray) -> np.ndarray:
    points_optical = (T_optical_world @ np.column_stack([points_world, np.ones(len(points_world))]).T)[:3]
    pixels = INTRINSICS.matrix() @ points_optical
    return (pixels[:2] / pixels[2]).T


def test_texture_decodes_as_its_id_and_not_when_mirrored() -> None:
    detector = cv2.aruco.ArucoDetector(
        cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50), cv2.aruco.DetectorParameters()
    )
    texture = cv2.copyMakeBorder(marker_texture(3), 40, 40, 40, 40, cv2.BORDER_CONSTANT, value=255)
    _, ids, _ = detector.detectMarkers(texture)
    assert ids is not None and ids.ravel().tolist() == [3]
    _, mirrored_ids, _ = detector.detectMarkers(cv2.flip(texture, 1))
    assert mirrored_ids is None
    # The refused ids are exactly the ones that survive mirroring.
    ambiguous = set()
    for marker_id in range(50):
        image = cv2.copyMakeBorder(marker_texture(marker_id), 40, 40, 40, 40, cv2.BORDER_CONSTANT, value=255)
        _, ids, _ = detector.detectMarkers(cv2.flip(image, 1))
        if ids is not None and marker_id in ids.ravel().tolist():
            ambiguous.add(marker_id)
    assert ambiguous == set(MIRROR_AMBIGUOUS_IDS)


@pytest.mark.parametrize("bad_id", [8, 9, 17, 47, -1, 50])
def test_refuses_ambiguous_and_unknown_ids(tmp_path: Path, bad_id: int) -> None:
    with pytest.raises(ValueError):
        marker_asset_paths(bad_id, tmp_path)


def test_assets_are_deterministic_and_reused(tmp_path: Path) -> None:
    obj_path, png_path = marker_asset_paths(5, tmp_path / "a")
    again_obj, again_png = marker_asset_paths(5, tmp_path / "a")
    other_obj, other_png = marker_asset_paths(5, tmp_path / "b")
    assert (again_obj, again_png) == (obj_path, png_path)
    assert obj_path.read_bytes() == other_obj.read_bytes()
    assert png_path.read_bytes() == other_png.read_bytes()
    assert "map_Kd" in obj_path.with_suffix(".mtl").read_text()
    assert sorted(path.suffix for path in obj_path.parent.iterdir()) == [".mtl", ".obj", ".png"]


def test_marker_shows_upright_from_the_front_and_blank_from_behind(client: int, tmp_path: Path) -> None:
    T_world_marker = make_transform((0.0, 0.0, 1.0), MARKER_FACING_X)
    marker_visual(client, 3, 0.1, T_world_marker, cache_dir=tmp_path)
    detector = cv2.aruco.ArucoDetector(
        cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50), cv2.aruco.DetectorParameters()
    )
    T_world_front = optical_frame_looking_at((0.8, 0.05, 1.1), (0.0, 0.0, 1.0))
    rgb, _ = render_rgbd(client, T_world_front, INTRINSICS)
    corners, ids, _ = detector.detectMarkers(rgb)
    assert ids is not None and ids.ravel().tolist() == [3]
    half = 0.05
    corners_world = (
        T_world_marker
        @ np.array([[-half, half, 0, 1], [half, half, 0, 1], [half, -half, 0, 1], [-half, -half, 0, 1]]).T
    )[:3].T
    expected = project(invert(T_world_front), corners_world)
    # Same corners in the same order: the texture is neither mirrored nor turned.
    assert np.max(np.abs(corners[0].reshape(4, 2) - expected)) < 1.5

    T_world_behind = optical_frame_looking_at((-0.8, 0.05, 1.1), (0.0, 0.0, 1.0))
    rgb_behind, _ = render_rgbd(client, T_world_behind, INTRINSICS)
    _, ids_behind, _ = detector.detectMarkers(rgb_behind)
    assert ids_behind is None
    assert rgb_behind.reshape(-1, 3).min() > 100  # the back is plain white-ish, no black cells


def test_intrinsics_defaults_match_the_tiago_head_camera() -> None:
    assert (INTRINSICS.width, INTRINSICS.height) == (640, 480)
    horizontal_fov = 2.0 * np.arctan(INTRINSICS.width / 2.0 / INTRINSICS.fx)
    assert np.degrees(horizontal_fov) == pytest.approx(63.0, abs=0.1)
    scaled = INTRINSICS.scaled(2)
    assert (scaled.width, scaled.fx, scaled.cx) == (1280, 2 * INTRINSICS.fx, 2 * INTRINSICS.cx + 0.5)


@pytest.mark.parametrize("supersample", [1, 2])
def test_pixels_and_depth_follow_the_pinhole_model(client: int, supersample: int) -> None:
    """Box edges fall where K predicts (pixel centres at integers) and depth is metric."""
    face_x = 0.01
    visual = p.createVisualShape(
        p.GEOM_BOX, halfExtents=[face_x, 0.2, 0.2], rgbaColor=[0, 0, 0, 1], physicsClientId=client
    )
    p.createMultiBody(0.0, -1, visual, [0.0, 0.0, 1.0], physicsClientId=client)
    for step in range(6):
        offset = 0.00037 * step
        eye = np.array([0.8, offset, 1.0 + 0.7 * offset])
        T_world_optical = optical_frame_looking_at(eye, eye - np.array([1.0, 0.0, 0.0]))
        rgb, depth_m = render_rgbd(client, T_world_optical, INTRINSICS, supersample=supersample)
        assert rgb.shape == (480, 640, 3) and rgb.dtype == np.uint8
        assert depth_m.shape == (480, 640) and depth_m.dtype == np.float32
        assert depth_m[240, 320] == pytest.approx(0.8 - face_x, abs=1e-3)
        assert depth_m[5, 5] == pytest.approx(INTRINSICS.far, rel=1e-3)
        corners = project(invert(T_world_optical), np.array([[face_x, -0.2, 1.2], [face_x, 0.2, 0.8]]))
        left, top = corners.min(axis=0)
        right, bottom = corners.max(axis=0)
        row, column = rgb[240, :, 0].astype(float), rgb[:, 320, 0].astype(float)
        if supersample == 1:
            # Without anti-aliasing a pixel is covered exactly when its centre is inside.
            black_columns, black_rows = np.nonzero(row < 50)[0], np.nonzero(column < 50)[0]
            assert black_columns[0] == np.floor(left) + 1
            assert black_columns[-1] == np.ceil(right) - 1
            assert black_rows[0] == np.floor(top) + 1
            assert black_rows[-1] == np.ceil(bottom) - 1
        else:
            # Averaged sub-samples: the edge pixel's grey level is its uncovered fraction.
            background = float(rgb[5, 5, 0])
            pixel = int(np.floor(left + 0.5))
            measured_left = pixel - 0.5 + row[pixel] / background
            pixel = int(np.floor(top + 0.5))
            measured_top = pixel - 0.5 + column[pixel] / background
            assert abs(measured_left - left) <= 0.25 and abs(measured_top - top) <= 0.25


def test_render_time_is_reported(client: int, tmp_path: Path) -> None:
    import time

    marker_visual(client, 3, 0.1, make_transform((0.0, 0.0, 1.0), MARKER_FACING_X), cache_dir=tmp_path)
    T_world_optical = optical_frame_looking_at((0.8, 0.0, 1.0), (0.0, 0.0, 1.0))
    timings = {}
    for supersample in (1, 2):
        render_rgbd(client, T_world_optical, INTRINSICS, supersample=supersample)
        start = time.perf_counter()
        for _ in range(3):
            render_rgbd(client, T_world_optical, INTRINSICS, supersample=supersample)
        timings[supersample] = (time.perf_counter() - start) / 3
    print(f"render_rgbd 640x480: {timings[1] * 1e3:.0f} ms, 2x supersampled: {timings[2] * 1e3:.0f} ms")
    # Generous bounds on a shared 2-core machine; they catch a renderer fallback gone wrong.
    assert timings[1] < 1.0 and timings[2] < 3.0
