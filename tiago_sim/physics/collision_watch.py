"""Collision honesty: contacts between the robot and the lab that no plan intended, from physics.

Why: the base is kinematic (a constraint pulls it along its commanded path), so nothing stops it
from driving through a bench; the arm may graze a bench top or a nest bracket. A real robot's
bumpers and motor-current monitors notice; here PyBullet's contact points after every step do.
Every robot link counts (base, wheels, torso, head, arms, grippers, the hotel tray). What it may
touch: plates (grasping, carrying and setting them down touch them by design), the floor, and the
dock with the base's back (its contact plate closes the charging circuit). Everything else
- a bench (its table), a nest bracket, a marker stand, a free-standing obstacle, a wall - is an
unintended contact: it is reported once when it starts (a link and a thing touching for many steps
is one collision), with the depth at its deepest first step.
Lives on the sim thread.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import pybullet as p

from tiago_sim.physics.robot_body import RobotBody
from tiago_sim.physics.scene import Scene

log = logging.getLogger(__name__)

COLLISION = "COLLISION"
"""Error code of a goal stopped by a collision (labware_interfaces ErrorCodes gets it at merge)."""
TOUCH_DISTANCE_M = 0.0
"""A contact point at this distance or closer (negative: penetration) is a touch; Bullet also
reports points up to its contact-breaking threshold (2 cm) apart, which are not touches."""
DOCK_LINKS = frozenset({"base_footprint", "base_link"})
"""The robot links that touch the dock by design."""
DOCK_CONTACT_HALF_ANGLE = math.radians(45.0)
"""The charging contacts are on the base's back: the base touches the dock by design within this of
straight behind it (docking ends a few degrees off at most); its front or side meeting the dock is a
collision (a final approach drove the base's side into it, and it was not reported)."""
NEAR_MISS_M = 0.01
"""Closer than this without touching is a near miss: logged (INFO) with the closest approach per
link and thing, so a run's log says how much room the arm and base really had. Bullet's contact
points hold touching pairs only, so near misses come from closest-point queries, every
NEAR_MISS_PERIOD_S of sim time (the arm moves at most 1.5 cm in it near a bench), only for things
within REACH_M. A measuring tool, off unless asked for (``near_misses=True``; the sim node's
``--near-misses``): it costs CPU on every review, and whether Bullet's closest-point queries
leave its contact state untouched was not proven (a trial's placement failed more often with them
on than off)."""
NEAR_MISS_PERIOD_S = 0.02
REACH_M = 1.2
"""Only things whose box lies within this of the base centre are queried for near misses (the arm
reaches about 0.9 m): a closest-point query against all ~15 things cost 0.2 ms, half a step."""
BASE_TOP_M = 0.30
"""PyBullet merges the fixed base, its cover and the hotel tray into one link (base_footprint);
a contact above the base's top (0.297 m) is the hotel tray's (or its post's)."""


@dataclass(frozen=True)
class Collision:
    """One unintended contact: which robot link touched what, how deep, where, when."""

    link: str
    thing: str
    depth_m: float
    position: tuple[float, float, float]
    sim_time: float

    def text(self) -> str:
        x, y, z = self.position
        return (
            f"{self.link} touched {self.thing} ({self.depth_m * 1000:.1f} mm deep at "
            f"({x:.2f}, {y:.2f}, {z:.2f}) m, t = {self.sim_time:.1f} s)"
        )


def _things(scene: Scene) -> dict[int, str]:
    """Body id -> what the messages call it."""
    things = {body: f"{name} table" for name, body in scene.tables.items()}
    things.update({body: f"{nest.station} nest {nest.sub_position}" for nest, body in scene.nests.items()})
    things.update({body: f"{name} marker stand" for name, body in scene.marker_stands.items()})
    things.update({body: f"obstacle {name}" for name, body in scene.obstacles.items()})
    things.update({body: f"the {name}" for name, body in scene.walls.items()})
    things[scene.dock] = "the dock"
    return things


class CollisionWatch:
    """Checks the robot's contact points after each physics step; keeps every collision seen."""

    def __init__(self, client: int, robot: RobotBody, scene: Scene, *, near_misses: bool = False) -> None:
        self.client = client
        self.robot = robot
        self.things = _things(scene)
        self.dock = scene.dock
        self.link_names = {index: name for name, index in robot.link_index.items()}
        self.touching: set[tuple[int, int]] = set()  # (link index, body) touching after the last step
        self.points: tuple = ()  # the robot's contact points after the last step (pybullet's tuples)
        self.collisions: list[Collision] = []
        self.near_misses: dict[tuple[str, str], float] = {}  # (link, thing) -> closest approach (m)
        self.near_miss_period_s = NEAR_MISS_PERIOD_S if near_misses else math.inf
        self._reviewed_at = -1.0
        self._boxes = {body: p.getAABB(body, physicsClientId=client) for body in self.things}

    def _review_near_misses(self) -> None:
        x, y, _ = self.robot.base_xy_yaw()
        for body, thing in self.things.items():
            (low_x, low_y, _), (high_x, high_y, _) = self._boxes[body]
            if max(low_x - x, x - high_x, low_y - y, y - high_y) > REACH_M:
                continue
            for point in p.getClosestPoints(self.robot.id, body, NEAR_MISS_M, physicsClientId=self.client):
                link, distance = point[3], point[8]
                if distance <= TOUCH_DISTANCE_M or (
                    body == self.dock and self._charging_contact(link, point[5])
                ):
                    continue
                key = (self._link_name(link, point[5]), thing)
                if distance < self.near_misses.get(key, NEAR_MISS_M) - 0.001:  # a new closest, by 1 mm
                    self.near_misses[key] = distance
                    log.info("near miss: %s came within %.1f mm of %s", key[0], distance * 1000, thing)

    def _link_name(self, link: int, position: tuple[float, float, float]) -> str:
        name = self.link_names.get(link, f"link {link}")
        if link == -1:
            return (
                "the hotel tray (base_footprint)" if position[2] > BASE_TOP_M else "the base (base_footprint)"
            )
        return name

    def _charging_contact(self, link: int, position: tuple[float, float, float]) -> bool:
        """A base contact with the dock behind the base, below its top: where the charging contacts are."""
        if self.link_names.get(link, "") not in DOCK_LINKS or position[2] > BASE_TOP_M:
            return False
        x, y, yaw = self.robot.base_xy_yaw()
        bearing = math.atan2(position[1] - y, position[0] - x) - yaw
        return abs(math.atan2(math.sin(bearing), -math.cos(bearing))) <= DOCK_CONTACT_HALF_ANGLE

    def check(self, sim_time: float) -> list[Collision]:
        """The unintended contacts that started in the last step (each also kept in ``collisions``)."""
        deepest: dict[tuple[int, int], tuple[float, tuple[float, float, float]]] = {}
        self.points = p.getContactPoints(bodyA=self.robot.id, physicsClientId=self.client)
        for point in self.points:
            body, link, distance = point[2], point[3], point[8]
            if body not in self.things or (body == self.dock and self._charging_contact(link, point[5])):
                continue
            if distance > TOUCH_DISTANCE_M:
                continue
            key = (link, body)
            if key not in deepest or -distance > deepest[key][0]:
                deepest[key] = (-distance, tuple(point[5]))
        started = [
            Collision(self._link_name(link, position), self.things[body], depth, position, sim_time)
            for (link, body), (depth, position) in deepest.items()
            if (link, body) not in self.touching
        ]
        self.touching = set(deepest)
        if sim_time - self._reviewed_at >= self.near_miss_period_s:
            self._reviewed_at = sim_time
            self._review_near_misses()
        for collision in started:
            log.warning("collision: %s", collision.text())
        self.collisions.extend(started)
        return started
