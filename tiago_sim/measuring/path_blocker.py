"""Fault injection: a box that is not on the map appears on the robot's path during a drive.

Why a real collision body: the robot must find it with its base laser (PyBullet ray casts hit it)
and the collision watch must catch it if the robot touched it; nothing tells the robot software.
The sim node's parameter ``fault.block_path`` arms it (parse_block_path says the forms):

- ``"1.0"``: once the base next drives along a planned path, a box (BOX_SIZE) stands across the
  path with its near face 1.0 m ahead of the base's front, measured along the path; the room
  around it is left as it was, so a way round may exist.
- ``"closed"`` (or ``"closed:1.5"``): the same, but a wall as long as the floor is wide, so the
  corridor (the whole lab, in fact) is closed between the robot and its goal.

Empty clears it (the box goes). The box stays until then, so a test can go on and watch the
robot replan. While it stands, the base's closest approach to it (ground truth: the true base
pose, the base as its 0.265 m circle) is kept and logged when it is cleared.
Runs on: the sim thread (it creates PyBullet bodies).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import pybullet as p

from tiago_description.robot_model import BASE_RADIUS
from tiago_sim.measuring.fault_injection import DRIVING_SPEED_M_S
from tiago_sim.navigation.planner import Plan

log = logging.getLogger(__name__)

BOX_SIZE = (0.30, 0.50, 0.50)
"""Depth along the path, width across it, height (m): a crate or a trolley's side; taller than
the base laser (0.0945 m), lower than the folded arms (0.74 m up)."""
CLOSED = "closed"
CLOSED_AHEAD_M = 1.0
AHEAD_RANGE_M = (0.3, 6.0)
"""Accepted distances ahead of the base's front (m)."""


@dataclass(frozen=True)
class BlockRequest:
    """Where the box goes: ``ahead_m`` from the base's front along the path; ``closed``: floor-wide."""

    ahead_m: float
    closed: bool


def parse_block_path(value: str) -> BlockRequest | None:
    """``""`` -> None (no box); ``"1.0"``, ``"closed"``, ``"closed:1.5"``; raises ValueError naming
    the value and the accepted forms."""
    text = value.strip().lower()
    if not text:
        return None
    closed = text == CLOSED or text.startswith(CLOSED + ":")
    number = text.split(":", 1)[1] if closed and ":" in text else (str(CLOSED_AHEAD_M) if closed else text)
    try:
        ahead_m = float(number)
    except ValueError:
        ahead_m = math.nan
    if not AHEAD_RANGE_M[0] <= ahead_m <= AHEAD_RANGE_M[1]:
        raise ValueError(
            f"fault.block_path {value!r}: give metres ahead of the robot ({AHEAD_RANGE_M[0]} to "
            f"{AHEAD_RANGE_M[1]}), 'closed' or 'closed:<metres>'"
        )
    return BlockRequest(ahead_m, closed)


def point_along(
    waypoints: tuple[tuple[float, float], ...], xy: tuple[float, float], ahead_m: float
) -> tuple[float, float, float]:
    """The point `ahead_m` along the polyline from the point on it nearest `xy`, and the polyline's
    heading there (clamped to its end)."""
    segments = list(zip(waypoints, waypoints[1:], strict=False))
    if not segments:
        raise ValueError("a path needs two waypoints")
    best = (math.inf, 0.0)  # distance from xy, path length there
    travelled = 0.0
    for (ax, ay), (bx, by) in segments:
        length = math.hypot(bx - ax, by - ay)
        share = 0.0 if length < 1e-9 else ((xy[0] - ax) * (bx - ax) + (xy[1] - ay) * (by - ay)) / length**2
        share = max(0.0, min(1.0, share))
        distance = math.hypot(ax + share * (bx - ax) - xy[0], ay + share * (by - ay) - xy[1])
        if distance < best[0]:
            best = (distance, travelled + share * length)
        travelled += length
    target = best[1] + ahead_m
    travelled = 0.0
    for index, ((ax, ay), (bx, by)) in enumerate(segments):
        length = math.hypot(bx - ax, by - ay)
        if travelled + length >= target or index == len(segments) - 1:
            heading = math.atan2(by - ay, bx - ax)
            along = min(max(target - travelled, 0.0), length)
            return ax + along * math.cos(heading), ay + along * math.sin(heading), heading
        travelled += length
    raise ValueError("a path needs two waypoints")


class PathBlocker:
    """At most one box; ``arm`` waits for the next drive, ``watch`` places it and follows the base."""

    def __init__(self, floor_size: float, current_plan: Callable[[], Plan | None]) -> None:
        self.floor_size = floor_size
        self.current_plan = current_plan
        self.request: BlockRequest | None = None
        self.body = -1
        self.box: tuple[float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0)  # x, y, yaw, l, w
        self.closest_m = math.inf

    def arm(self, sim: Any, request: BlockRequest) -> None:
        self.clear(sim)
        self.request = request
        log.info("a box will block the path %.2f m ahead during the next drive%s (fault injection)",
                 request.ahead_m, ", closing it" if request.closed else "")  # fmt: skip

    def watch(self, sim: Any) -> bool:
        """After every batch of steps while armed or standing: place the box once the base drives a
        plan; then keep the base's closest approach. True when there is nothing left to do."""
        if self.request is not None and self.body < 0:
            plan = self.current_plan()
            if abs(sim.base.v) < DRIVING_SPEED_M_S or plan is None:
                return False
            self._place(sim, plan, self.request)
        if self.body < 0:
            return True
        x, y, _ = sim.robot.base_xy_yaw()
        self.closest_m = min(self.closest_m, _circle_to_box_m((x, y), self.box))
        return False

    def clear(self, sim: Any) -> None:
        if self.body >= 0:
            p.removeBody(self.body, physicsClientId=sim.client_id)
            log.info("path-blocking box removed; the base came within %.3f m of it", self.closest_m)
        self.request, self.body, self.closest_m = None, -1, math.inf

    def _place(self, sim: Any, plan: Plan, request: BlockRequest) -> None:
        x, y, _ = sim.robot.base_xy_yaw()
        depth, width, height = BOX_SIZE
        if request.closed:
            width = 2 * self.floor_size
        cx, cy, yaw = point_along(plan.waypoints, (x, y), BASE_RADIUS + request.ahead_m + depth / 2)
        client = sim.client_id
        half = [depth / 2, width / 2, height / 2]
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
        orange = [0.8, 0.45, 0.1, 1]
        visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=orange, physicsClientId=client)
        quat = p.getQuaternionFromEuler([0.0, 0.0, yaw])
        self.body = p.createMultiBody(0.0, shape, visual, [cx, cy, height / 2], quat, physicsClientId=client)
        self.box = (cx, cy, yaw, depth, width)
        log.info(
            "path-blocking box at x=%.3f y=%.3f yaw=%.3f size %.2f x %.2f x %.2f m, the base at (%.2f, %.2f) "
            "driving %.2f m/s (fault injection)", cx, cy, yaw, depth, width, height, x, y, sim.base.v,
        )  # fmt: skip


def _circle_to_box_m(xy: tuple[float, float], box: tuple[float, float, float, float, float]) -> float:
    """Distance from the base (a BASE_RADIUS circle at xy) to a rectangle (x, y, yaw, length, width)."""
    bx, by, yaw, length, width = box
    dx, dy = xy[0] - bx, xy[1] - by
    along = dx * math.cos(yaw) + dy * math.sin(yaw)
    across = -dx * math.sin(yaw) + dy * math.cos(yaw)
    outside = math.hypot(max(abs(along) - length / 2, 0.0), max(abs(across) - width / 2, 0.0))
    return outside - BASE_RADIUS
