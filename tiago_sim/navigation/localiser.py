"""Localisation: the base's pose in the map from wheel odometry and base laser scans.

Why this shape (an EKF-like tracker with a scan matcher, not a particle filter): the robot starts
at a known place (docked: the dock is drawn in the world file) and never gets lost between scans
taken a few times a second, so the posterior stays one peak; a matcher on the map's distance
field places a scan to millimetres with ~600 beams where a particle filter of a few hundred
particles jitters by centimetres and costs tens of times more CPU, which the simulation's
real-time factor cannot spare. What it gives up: global relocalisation (a robot carried
elsewhere while switched off). Each update predicts the pose from the odometry since the last
one (covariance grown by a wheel-slip model), then matches the scan around that prediction
(scan_matcher). A match with too few endpoints on mapped surfaces, or whose pose lies implausibly
far from the prediction, is dropped and odometry alone carries on.
The correction published to the base is ``map_from_odom`` = pose in map composed with the inverse
of the odometry of the same instant. Pure numpy; lives on whichever thread calls it.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from tiago_description.transforms import Planar, compose_planar, invert_planar
from tiago_sim.navigation.likelihood_field import LikelihoodField
from tiago_sim.navigation.scan_matcher import ScanMatch, match_scan

log = logging.getLogger(__name__)

# Wheel-slip model (1 sigma): per metre driven and per radian turned, plus a floor. Generous
# against the drive's 0.05 to 0.2 % (a tile joint, a threshold) so that a scan is never overruled:
# a 2 % wheel radius difference turns the heading by 0.05 rad per metre driven.
SLIP_PER_METRE = 0.05  # m of position error per m driven
TURN_SLIP_PER_RADIAN = 0.05  # rad of heading error per rad turned
TURN_SLIP_PER_METRE = 0.05  # rad of heading error per m driven
INITIAL_SIGMA = (0.01, 0.01, math.radians(1.0))  # docked: the dock's place, within its contacts' play
MIN_INLIERS = 40  # endpoints on mapped surfaces for a scan to count
# A match that moves the pose farther than this many sigmas of the prediction is taken only if
# the scan fits the map well (its endpoints' rms distance to the surfaces near the range noise):
# a wrong local fit (one bench face taken for another) leaves many endpoints off the surfaces.
GATE_MAHALANOBIS = 4.0
GOOD_FIT_RMS_M = 0.035


@dataclass(frozen=True)
class LocalisationUpdate:
    """The outcome of one scan: the pose in the map, its covariance, and what the match did."""

    pose: Planar
    covariance: np.ndarray
    map_from_odom: Planar
    accepted: bool
    match: ScanMatch | None
    reason: str = ""


class Localiser:
    """Tracks the base's pose in the map; ``update`` once per scan."""

    def __init__(
        self,
        field: LikelihoodField,
        initial_pose: Planar,
        initial_odometry: Planar,
        *,
        initial_sigma: Planar = INITIAL_SIGMA,
        range_sigma_m: float = 0.02,
    ) -> None:
        self.field = field
        self.range_sigma_m = range_sigma_m
        self.pose = initial_pose
        self.covariance = np.diag(np.square(initial_sigma))
        self.last_odometry = initial_odometry
        self.updates = 0
        self.rejected = 0

    def map_from_odom(self, odometry: Planar) -> Planar:
        """The odometry frame's pose in the map, from the current estimate and that odometry."""
        return compose_planar(self.pose, invert_planar(odometry))

    def predict(self, odometry: Planar) -> None:
        """Move the estimate by the odometry since the last call; grow its covariance."""
        delta = compose_planar(invert_planar(self.last_odometry), odometry)
        self.last_odometry = odometry
        distance, turn = math.hypot(delta[0], delta[1]), abs(delta[2])
        yaw = self.pose[2]
        c, s = math.cos(yaw), math.sin(yaw)
        # Jacobian of the pose after the step with respect to the pose before it
        jacobian = np.array(
            [[1.0, 0.0, -s * delta[0] - c * delta[1]], [0.0, 1.0, c * delta[0] - s * delta[1]], [0, 0, 1.0]]
        )
        position_sigma = SLIP_PER_METRE * distance + 1e-4
        yaw_sigma = TURN_SLIP_PER_RADIAN * turn + TURN_SLIP_PER_METRE * distance + 1e-4
        noise = np.diag([position_sigma**2, position_sigma**2, yaw_sigma**2])
        self.pose = compose_planar(self.pose, delta)
        self.covariance = jacobian @ self.covariance @ jacobian.T + noise

    def update(self, odometry: Planar, points: np.ndarray) -> LocalisationUpdate:
        """Predict to ``odometry`` (taken with the scan), then correct with the scan's endpoints
        (N, 2) in base_footprint."""
        self.predict(odometry)
        self.updates += 1
        match = match_scan(self.field, points, self.pose, self.covariance, self.range_sigma_m)
        offset = np.array(match.pose) - np.array(self.pose)
        offset[2] = math.remainder(offset[2], math.tau)
        distance = float(math.sqrt(offset @ np.linalg.solve(self.covariance, offset)))
        reason = ""
        if match.inliers < MIN_INLIERS:
            reason = f"{match.inliers} endpoints on mapped surfaces, fewer than {MIN_INLIERS}"
        elif distance > GATE_MAHALANOBIS and match.rms_m > GOOD_FIT_RMS_M:
            reason = (
                f"the match moves the pose {distance:.1f} sigma from the prediction and fits the map "
                f"to {100 * match.rms_m:.1f} cm rms"
            )
        if reason:
            self.rejected += 1
            log.debug("scan dropped: %s", reason)
        else:
            self.pose, self.covariance = match.pose, match.covariance
        return LocalisationUpdate(
            self.pose, self.covariance.copy(), self.map_from_odom(odometry), not reason, match, reason
        )
