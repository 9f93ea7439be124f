"""What the head camera's sensor adds to a perfect rendering: read noise on colour, noise and bias on depth.

Why: PyBullet renders exact colours and exact depth. The robot software refines the marker pose
with depth (perception.aruco fits a plane to the marker's depth pixels), so exact depth would make
that step look better than any real RGB-D camera allows.

Depth model (the head camera of a TIAGo++ is a structured-light RGB-D camera of the PrimeSense
kind): per-pixel Gaussian axial noise that grows with distance as Nguyen, Izadi and Lovell measured
on a Kinect (3DIMPVT 2012): sigma(z) = 1.2 mm + 1.9 mm/m^2 (z - 0.4 m)^2, which is 1.9 mm at 1 m,
scaled so that ``depth_noise_m`` is sigma at 1 m; plus one depth bias per trial (a residual of the
depth calibration), ``bias_at_1m`` times (z / 1 m)^2, the same z^2 law Khoshelham and Elberink
(Sensors 2012) found for the Kinect's errors. Pixels that saw nothing (at the far clip) stay as
they are. Kept ideal: the noise is independent from pixel to pixel (a real depth image is smoother
and blockier, so a plane fit averages less of it away), there is no disparity quantisation (about
3 mm steps at 1 m for a PrimeSense camera) and no lateral (edge) noise; the bias level stands in
for what these would leave in a plane fit. Colour gets Gaussian read noise in grey levels.

Each stream is seeded from the trial seed, so a replay draws the same noise for the same sequence
of images. Pure functions; the returned wrapper runs on whichever thread renders (the sim thread).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

NOISE_AT_NEAR_M = 0.0012  # Nguyen et al.: sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2, z in m
NOISE_GROWTH_PER_M2 = 0.0019
NOISE_MODEL_ORIGIN_M = 0.4


def nguyen_axial_sigma(depth_m: np.ndarray) -> np.ndarray:
    """The Kinect's measured axial noise (m, one sigma) at these distances (m)."""
    return NOISE_AT_NEAR_M + NOISE_GROWTH_PER_M2 * (depth_m - NOISE_MODEL_ORIGIN_M) ** 2


def depth_sigma(depth_m: np.ndarray, sigma_at_1m: float) -> np.ndarray:
    """Per-pixel noise (m) of the model above, scaled to ``sigma_at_1m`` at 1 m."""
    return sigma_at_1m * nguyen_axial_sigma(depth_m) / float(nguyen_axial_sigma(np.array(1.0)))


def noisy_depth(
    depth_m: np.ndarray, sigma_at_1m: float, bias_at_1m: float, far_m: float, rng: np.random.Generator
) -> np.ndarray:
    """Depth as the sensor would report it: bias and noise on every pixel that saw a surface."""
    if sigma_at_1m <= 0.0 and bias_at_1m == 0.0:
        return depth_m
    depth = depth_m.astype(np.float64)
    seen = depth < far_m * 0.999
    noise = rng.standard_normal(depth.shape) * depth_sigma(depth, sigma_at_1m) if sigma_at_1m > 0 else 0.0
    measured = depth + bias_at_1m * depth**2 + noise
    return np.where(seen, measured, depth).astype(np.float32)


def noisy_camera(
    render: Callable[..., tuple[np.ndarray, np.ndarray, Any]],
    sigma_levels: float,
    seed: int,
    depth_sigma_at_1m: float = 0.0,
    depth_bias_at_1m: float = 0.0,
) -> Callable[..., tuple[np.ndarray, np.ndarray, Any]]:
    """Wrap a head-camera render function: read noise on colour, the depth model above (seeded)."""
    colour_rng = np.random.default_rng([seed, 0xCA])
    depth_rng = np.random.default_rng([seed, 0xDE])

    def render_with_noise(*args: Any, **kwargs: Any) -> tuple[np.ndarray, np.ndarray, Any]:
        rgb, depth, intrinsics = render(*args, **kwargs)
        if sigma_levels > 0.0:
            noise = colour_rng.normal(0.0, sigma_levels, size=rgb.shape)
            rgb = np.clip(rgb.astype(np.float32) + noise, 0, 255).astype(np.uint8)
        depth = noisy_depth(depth, depth_sigma_at_1m, depth_bias_at_1m, intrinsics.far, depth_rng)
        return rgb, depth, intrinsics

    return render_with_noise
