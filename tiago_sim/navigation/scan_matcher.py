"""Scan-to-map matching: the base pose that lays a laser scan's endpoints onto the map's surfaces.

Method: Gauss-Newton on the signed distance field (likelihood_field), seeded and regularised by
the pose predicted from odometry (a maximum a posteriori estimate: scan residuals plus the
prediction's own covariance), so a direction the scan cannot see (a single flat bench face) stays
where odometry put it instead of sliding. Robust to things that are not on the map (a box, a
person, the dock): endpoints farther than ``outlier_m`` from every mapped surface are dropped, and
the rest weighted with a Huber kernel, so a cart beside a bench bends the pose by millimetres, not
centimetres. Pure numpy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tiago_description.transforms import Planar
from tiago_sim.navigation.likelihood_field import LikelihoodField

HUBER_M = 0.03  # residuals below it count fully (two sigma of the laser's range noise)
OUTLIER_M = 0.25  # first pass: farther from any mapped surface is not on the map
OUTLIER_FINAL_M = 0.10  # once the pose has converged
# Beams of one scan share the map's errors (outline rasterised to 1 cm, benches nudged since the
# map was drawn), so they are not independent: count one beam in this many for the covariance.
BEAMS_PER_INDEPENDENT = 10
ITERATIONS = 12


@dataclass(frozen=True)
class ScanMatch:
    """The matched pose, its covariance (3x3: x, y, yaw) and how well the scan fitted."""

    pose: Planar
    covariance: np.ndarray
    inliers: int
    rms_m: float  # of the inliers' distances to the map


def scan_points(
    ranges: np.ndarray, angles: np.ndarray, mount: Planar, range_min: float, range_max: float
) -> np.ndarray:
    """Endpoints (N, 2) in base_footprint of the beams that returned within the sensor's range."""
    valid = np.isfinite(ranges) & (ranges >= range_min) & (ranges <= range_max)
    r, a = ranges[valid], angles[valid] + mount[2]
    return np.stack([mount[0] + r * np.cos(a), mount[1] + r * np.sin(a)], axis=1)


def match_scan(
    field: LikelihoodField,
    points: np.ndarray,
    prior: Planar,
    prior_covariance: np.ndarray,
    range_sigma_m: float,
) -> ScanMatch:
    """Best pose for endpoints ``points`` (base frame) near ``prior``; see the module docstring."""
    prior_information = np.linalg.inv(prior_covariance)
    pose = np.array(prior, dtype=float)
    beam_information = 1.0 / (range_sigma_m**2 * BEAMS_PER_INDEPENDENT)
    hessian = prior_information
    inliers = np.zeros(len(points), dtype=bool)
    distances = np.zeros(len(points))
    for iteration in range(ITERATIONS):
        c, s = math.cos(pose[2]), math.sin(pose[2])
        world = points @ np.array([[c, s], [-s, c]]) + pose[:2]
        distances, gradients = field.sample(world)
        limit = OUTLIER_M if iteration < 3 else OUTLIER_FINAL_M
        inliers = np.abs(distances) < limit
        r, g, p = distances[inliers], gradients[inliers], points[inliers]
        weights = np.minimum(1.0, HUBER_M / np.maximum(np.abs(r), 1e-9)) * beam_information
        jacobian = np.empty((len(r), 3))
        jacobian[:, :2] = g
        jacobian[:, 2] = g[:, 0] * (-s * p[:, 0] - c * p[:, 1]) + g[:, 1] * (c * p[:, 0] - s * p[:, 1])
        offset = pose - np.array(prior)
        offset[2] = math.remainder(offset[2], math.tau)
        hessian = jacobian.T @ (jacobian * weights[:, None]) + prior_information
        gradient = jacobian.T @ (weights * r) + prior_information @ offset
        step = -np.linalg.solve(hessian, gradient)
        pose += step
        if abs(step[0]) + abs(step[1]) < 1e-4 and abs(step[2]) < 1e-4 and iteration >= 3:
            break
    pose[2] = math.remainder(pose[2], math.tau)
    kept = distances[inliers]
    rms = float(np.sqrt(np.mean(kept**2))) if len(kept) else math.inf
    return ScanMatch(
        (float(pose[0]), float(pose[1]), float(pose[2])), np.linalg.inv(hessian), int(inliers.sum()), rms
    )
