"""How well the skills' marker detector sees a marker from the side: detection and pose error by obliquity.

Why: the loader refuses a station whose marker the head camera sees more than
`MARKER_MAX_OBLIQUITY_DEG` off its face's normal, and most view refusals of drawn lab furniture are
61 to 78 deg (a marker beside a long row, seen from the working pose). This measures the detector
(`tiago_skills.perception.aruco.detect_marker`, with depth, as the skills call it) on the simulator's
rendering with the default camera noise (colour read noise 2 grey levels, depth noise 1.9 mm at
1 m), over the distances and marker sizes drawn lab furniture has, and prints per obliquity bin the
detection rate and the position and heading errors that matter for a nest up to 0.5 m from its
marker. Ground truth is only the expectation here. It lives with the start-up because it joins the
skills' detector to the simulator's camera, as the twin does.

    python -m tiago_twin.marker_obliquity [--views 40] [--seed 1]
"""

from __future__ import annotations

import argparse
import logging
import math
import sys
import tempfile
from pathlib import Path

import numpy as np
import pybullet as p

from tiago_description.transforms import invert, make_transform, rotation_angle
from tiago_sim.measuring.camera_noise import noisy_depth
from tiago_sim.physics.camera import CameraIntrinsics, optical_frame_looking_at, render_rgbd
from tiago_sim.physics.marker_asset import marker_visual
from tiago_skills.perception.aruco import detect_marker

log = logging.getLogger(__name__)

BINS_DEG = (0, 30, 45, 55, 60, 65, 70, 75, 80, 85)
DISTANCES_M = (0.45, 1.0)
MARKER_SIZES_M = (0.10, 0.14)
COLOUR_NOISE_LEVELS = 2.0
DEPTH_NOISE_AT_1M = 0.0019
NEST_LEVER_M = 0.5
"""A nest lies up to this far from its marker: a heading error of the marker moves it by this lever."""
# Marker facing +x (x = world +y, y = world up), upright, as a station's marker stands.
MARKER_FACING_X = np.column_stack([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])


def view(rng: np.random.Generator, obliquity_deg: float, T_world_marker: np.ndarray) -> np.ndarray:
    """A camera pose this far off the marker's normal (sideways and down, as a head looks at a marker
    beside a row), at a drawn distance, aimed at the marker's centre give or take a few cm."""
    distance = rng.uniform(*DISTANCES_M)
    off = math.radians(obliquity_deg + rng.uniform(-2.0, 2.0))
    up = min(math.sin(math.radians(rng.uniform(10.0, 40.0))), math.sin(off))  # the head looks down
    side = math.sqrt(max(math.sin(off) ** 2 - up**2, 0.0)) * rng.choice((-1.0, 1.0))
    direction = np.array([side, up, math.cos(off)])  # in the marker frame: x right, y up, z out
    eye = (T_world_marker @ np.append(distance * direction, 1.0))[:3]
    target = T_world_marker[:3, 3] + rng.normal(0.0, 0.03, 3)
    return optical_frame_looking_at(eye, target, 0.0)


def measure(views: int, seed: int) -> list[dict[str, float]]:
    rng = np.random.default_rng(seed)
    intrinsics = CameraIntrinsics()
    rows = []
    client = p.connect(p.DIRECT)
    try:
        with tempfile.TemporaryDirectory() as cache:
            markers = {}
            for index, size in enumerate(MARKER_SIZES_M):
                T = make_transform((0.0, 3.0 * index, 1.0), MARKER_FACING_X)
                marker_visual(client, 3, size, T, cache_dir=Path(cache))
                markers[size] = T
            for obliquity in BINS_DEG:
                seen, positions, headings = 0, [], []
                for _ in range(views):
                    size = float(rng.choice(MARKER_SIZES_M))
                    T_world_marker = markers[size]
                    T_world_optical = view(rng, obliquity, T_world_marker)
                    rgb, depth = render_rgbd(client, T_world_optical, intrinsics)
                    noise = rng.normal(0.0, COLOUR_NOISE_LEVELS, rgb.shape)
                    rgb = np.clip(rgb.astype(np.float32) + noise, 0, 255).astype(np.uint8)
                    depth = noisy_depth(depth, DEPTH_NOISE_AT_1M, 0.0, intrinsics.far, rng)
                    found = detect_marker(rgb, intrinsics, 3, size, depth_m=depth)
                    if found is None:
                        continue
                    seen += 1
                    truth = invert(T_world_optical) @ T_world_marker
                    positions.append(float(np.linalg.norm(found.T_optical_marker[:3, 3] - truth[:3, 3])))
                    headings.append(
                        math.degrees(rotation_angle(found.T_optical_marker[:3, :3], truth[:3, :3]))
                    )
                rows.append(_row(obliquity, views, seen, positions, headings))
    finally:
        p.disconnect(client)
    return rows


def _row(obliquity: float, views: int, seen: int, positions: list[float], headings: list[float]) -> dict:
    def q(values: list[float], at: float, scale: float) -> float:
        return float(np.quantile(values, at)) * scale if values else math.nan

    return {
        "obliquity_deg": obliquity,
        "detected_pct": 100.0 * seen / views,
        "position_median_mm": q(positions, 0.5, 1000),
        "position_p95_mm": q(positions, 0.95, 1000),
        "angle_median_deg": q(headings, 0.5, 1),
        "angle_p95_deg": q(headings, 0.95, 1),
        "nest_p95_mm": q(positions, 0.95, 1000) + 1000 * NEST_LEVER_M * math.radians(q(headings, 0.95, 1)),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--views", type=int, default=40, help="views per obliquity bin")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    rows = measure(args.views, args.seed)
    out = sys.stdout
    out.write("| obliquity (deg) | detected | position median / p95 (mm) | angle median / p95 (deg) |")
    out.write(" nest 0.5 m away, p95 (mm) |\n")
    out.write("|---:|---:|---:|---:|---:|\n")
    for r in rows:
        out.write(
            f"| {r['obliquity_deg']:.0f} | {r['detected_pct']:.0f} % | {r['position_median_mm']:.1f} / "
            f"{r['position_p95_mm']:.1f} | {r['angle_median_deg']:.2f} / {r['angle_p95_deg']:.2f} | "
            f"{r['nest_p95_mm']:.1f} |\n"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
