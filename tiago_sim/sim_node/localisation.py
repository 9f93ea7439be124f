"""The robot's localisation loop: base laser scans matched against the map a few times a second.

Why on the simulation clock (SimClock) and not a wall-clock timer: scan, odometry and the
correction must belong to one instant of simulated time, and a run must be reproducible from its
seed whatever the machine's load. Why a match only after the base moved some centimetres (plus
a few once it stops): odometry drifts by well under a millimetre in between, a standing base's
odometry does not change, so further scans could only average the range noise down, and the sim
thread's CPU is what the real-time factor is made of. A scan at rest is still taken every
``REST_SCAN_PERIOD_S`` while someone reads them (``scans_wanted``: /scan has
subscribers).

The correction goes to the base through ``DiffDriveBase.correct`` (applied at once at rest,
rate-limited during a drive, held during a relative drive). Ground truth is never read here.
Lives on the sim thread (SimClock calls ``_tick``); ``latest`` and ``latest_scan`` are replaced
whole, so other threads may read them.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from typing import Any

from lab_description.world import World
from tiago_sim.navigation.likelihood_field import LikelihoodField
from tiago_sim.navigation.localiser import LocalisationUpdate, Localiser
from tiago_sim.navigation.occupancy_map import build_map
from tiago_sim.navigation.scan_matcher import scan_points
from tiago_sim.physics.base_laser import LaserReading

log = logging.getLogger(__name__)

PERIOD_S = 0.2  # the loop looks at odometry 5 times a second (20 cm apart at TIAGo's top speed)
# A scan is matched once the base has moved this far since the last match (nav2's AMCL waits for
# 0.25 m or 0.2 rad by default): every second look at top speed, every look at the final
# approach's 0.3 m/s. Odometry drifts well under a millimetre over that.
MATCH_AFTER_M, MATCH_AFTER_RAD = 0.15, 0.15
REST_UPDATES = 2  # scans matched once the base stands, to settle the pose where work happens
REST_SCAN_PERIOD_S = 1.0  # scans for /scan only, while the base stands
MAP_RESOLUTION = 0.01  # m: the localiser's own rasterisation of the world (surfaces within 5 mm)
# odometry change within one period that counts as driving (a base that creeps by less, as it does
# under arm motions, stands)
MOVING_M, MOVING_RAD = 1e-3, 1e-3


@dataclass(frozen=True)
class Localised:
    """One localisation update and the simulated time of its scan."""

    sim_time: float
    update: LocalisationUpdate


@dataclass
class LocalisationCost:
    """CPU seconds of the sim thread spent on laser ray casting and on matching, and their counts."""

    scans: int = 0
    matches: int = 0
    scan_cpu_s: float = 0.0
    match_cpu_s: float = 0.0


class LocalisationLoop:
    """Owns the Localiser; registered on the Simulation's clock at construction (sim thread)."""

    def __init__(self, world: World, sim: Any, period_s: float = PERIOD_S) -> None:
        started = time.thread_time()
        self.field = LikelihoodField(build_map(world, MAP_RESOLUTION))
        dock = world.dock_pose  # the robot starts docked: the dock is a known place on the map
        self.localiser = Localiser(
            self.field, (dock.x, dock.y, dock.yaw), sim.odometry(), range_sigma_m=sim.laser.spec.range_noise_m
        )
        self.latest: Localised | None = None
        self.latest_scan: LaserReading | None = None
        # Scans at rest for whoever reads them (/scan has subscribers, obstacle checks): set from
        # outside; off, a standing base takes no scans beyond its last REST_UPDATES.
        self.scans_wanted = False
        self.cost = LocalisationCost()
        self._odometry = self._matched_odometry = sim.odometry()
        self._rest_updates = 0
        self._last_scan_s = -math.inf
        sim.clock.every(period_s, self._tick, sim.sim_time)
        log.info("localisation map built in %.2f s CPU", time.thread_time() - started)

    def _tick(self, sim: Any) -> None:
        odometry = sim.odometry()
        driving = _moved(self._odometry, odometry, MOVING_M, MOVING_RAD)
        self._odometry = odometry
        if driving:
            self._rest_updates = 0
        moved = _moved(self._matched_odometry, odometry, MATCH_AFTER_M, MATCH_AFTER_RAD)
        matching = moved or (not driving and self._rest_updates < REST_UPDATES)
        if not matching and (not self.scans_wanted or sim.sim_time - self._last_scan_s < REST_SCAN_PERIOD_S):
            return
        started = time.thread_time()
        reading = sim.laser.read(sim.sim_time, odometry)
        scanned = time.thread_time()
        self.latest_scan, self._last_scan_s = reading, sim.sim_time
        self.cost.scans += 1
        self.cost.scan_cpu_s += scanned - started
        if not matching:
            return
        self._rest_updates += 0 if driving else 1
        self._matched_odometry = odometry
        spec = reading.spec
        mount = (spec.mount_x, spec.mount_y, spec.mount_yaw)
        points = scan_points(reading.ranges, spec.angles(), mount, spec.range_min, spec.range_max)
        update = self.localiser.update(odometry, points)
        sim.base.correct(update.map_from_odom)
        self.latest = Localised(reading.sim_time, update)
        self.cost.matches += 1
        self.cost.match_cpu_s += time.thread_time() - scanned
        if self.cost.matches % 1000 == 0:
            self.log_cost()

    def log_cost(self) -> None:
        cost = self.cost
        log.info(
            "localisation: %d scans (%.2f ms CPU each), %d matches (%.2f ms each), %d dropped",
            cost.scans, 1e3 * cost.scan_cpu_s / max(cost.scans, 1), cost.matches,
            1e3 * cost.match_cpu_s / max(cost.matches, 1), self.localiser.rejected,
        )  # fmt: skip


def _moved(
    before: tuple[float, float, float], after: tuple[float, float, float], metres: float, radians: float
) -> bool:
    """Odometry moved at least ``metres`` or turned at least ``radians`` from ``before`` to ``after``."""
    shift = math.hypot(after[0] - before[0], after[1] - before[1])
    return shift >= metres or abs(math.remainder(after[2] - before[2], math.tau)) >= radians
