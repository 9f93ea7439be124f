"""Following a path while watching it with the base laser: stop short of what the map does not know.

Why a wrapper around the path motion and not a check in DriveMotion: the corridor to watch is the
rest of the whole path (past the next corner too), which only the path knows. At the start and
every ``LOOK_EVERY_M`` driven (or ``LOOK_EVERY_RAD`` turned) it takes a scan, puts its
endpoints into the map frame at the pose estimate of the same instant (the robot's belief, never
ground truth) and asks navigation.blockage whether unexplained points lie in the corridor ahead.
If so it cancels the drive: DriveMotion's cancel commands zero speed and the base ramps down
within TIAGo's linear and angular acceleration limits (a motion-level stop, not the collision
watch's protective stop); once the base stands the motion ends with ``PATH_BLOCKED`` and keeps
the blockage and every unexplained point near the robot for the replanner. Segments driven in
reverse are not watched (the laser looks ahead only). Lives on the sim thread.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from tiago_sim.navigation.blockage import Blockage, UnmappedObstacles, to_map_frame
from tiago_sim.navigation.planner import Plan
from tiago_sim.navigation.scan_matcher import scan_points
from tiago_sim.physics.motion import CANCELED, Motion, SequenceMotion

log = logging.getLogger(__name__)

PATH_BLOCKED = "PATH_BLOCKED"
"""Error code of a drive stopped short of an obstacle not on the map (navigation replans on it)."""
LOOK_EVERY_M, LOOK_EVERY_RAD = 0.10, 0.15
"""A look each time odometry moved 10 cm or turned 0.15 rad since the last one (10 Hz at top speed,
inside LOOKAHEAD_M's allowance): a scan costs the sim thread 1 to 4 ms of ray casting, and a base
that stands sees nothing new in its way. The TiM561 itself scans at 15 Hz."""


@dataclass(frozen=True)
class MapScan:
    """A scan's endpoints in the map frame (N, 2), at the pose estimate of the same instant; the
    laser's origin in the map and its beam spacing (for seeing through old marks)."""

    points: np.ndarray
    pose: tuple[float, float, float]
    origin: tuple[float, float]
    beam_rad: float


def scan_in_map(sim: Any) -> MapScan:
    """A scan now, in the map frame at the robot's own pose estimate (never ground truth)."""
    reading = sim.laser.read(sim.sim_time, sim.odometry())
    spec = reading.spec
    mount = (spec.mount_x, spec.mount_y, spec.mount_yaw)
    points = scan_points(reading.ranges, spec.angles(), mount, spec.range_min, spec.range_max)
    pose = sim.pose_estimate()
    ox, oy = to_map_frame(np.array([[spec.mount_x, spec.mount_y]]), pose)[0]
    return MapScan(to_map_frame(points, pose), pose, (float(ox), float(oy)), spec.angle_increment)


class GuardedPathMotion(Motion):
    """Runs a path motion (physics.path_following) and stops it short of unmapped obstacles."""

    def __init__(self, sim: Any, path: SequenceMotion, plan: Plan, obstacles: UnmappedObstacles) -> None:
        super().__init__(path.name, path.resources)
        self.sim = sim
        self.path = path
        self.plan = plan
        self.obstacles = obstacles
        self.blockage: Blockage | None = None
        self.seen = np.zeros((0, 2))  # unexplained points near the robot when it stopped
        self._looked_from: tuple[float, float, float] | None = None  # odometry at the last look
        self.remaining_s = path.remaining_s

    def cancel(self) -> None:
        super().cancel()
        self.path.cancel()

    def tick(self, dt: float) -> None:
        if self.blockage is None and not self.cancel_requested and self._moved_on():
            self._look()
        self.path.advance(dt)
        path = self.path
        self.phase, self.progress, self.remaining_s = path.phase, path.progress, path.remaining_s
        if not self.path.done:
            return
        if self.blockage is not None and self.path.error_code == CANCELED:
            self.finish(False, PATH_BLOCKED, f"stopped short of {self.blockage.text()}")
        else:
            self.finish(self.path.success, self.path.error_code, self.path.message)

    def _moved_on(self) -> bool:
        """True at the start and whenever odometry moved LOOK_EVERY_M or turned LOOK_EVERY_RAD since."""
        x, y, yaw = odometry = self.sim.odometry()
        if self._looked_from is not None:
            x0, y0, yaw0 = self._looked_from
            turned = abs(math.remainder(yaw - yaw0, math.tau))
            if math.hypot(x - x0, y - y0) < LOOK_EVERY_M and turned < LOOK_EVERY_RAD:
                return False
        self._looked_from = odometry
        return True

    def _look(self) -> None:
        segment = max(self.path.index, 0)
        waypoints = self.plan.waypoints
        last = len(waypoints) - 2
        if (segment == 0 and self.plan.reverse_first) or (segment == last and self.plan.reverse_last):
            return
        scan = scan_in_map(self.sim)
        points, pose = scan.points, scan.pose
        ahead = [pose[:2], *waypoints[segment + 1 :]]
        blockage = self.obstacles.blocking(points, ahead)
        if blockage is None:
            return
        self.blockage = blockage
        self.seen = self.obstacles.near_robot(points, pose[:2])
        log.info(
            "path blocked at sim %.2f s: %s (%d points); stopping at %.2f m/s",
            self.sim.sim_time, blockage.text(), len(blockage.points), self.sim.base.v,
        )  # fmt: skip
        self.path.cancel()
