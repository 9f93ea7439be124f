"""Plates the robot moves without holding them: which link pushed which plate how far, from physics.

Why: touching plates is part of grasping and placing, so the collision watch does not count it. But
a finger sweeping through a plate on its way to a nest pushed that plate out of its nest, and the
run's log showed only the later step's failure (the descent to grasp it stopped short).
This watch reports a touch that moved an unheld plate by more than PUSH_M, once per touch: what the
physics saw, for the log and the tests; it stops nothing (the robot's own sensors must notice).
Lives on the sim thread; reads the contact points the collision watch fetched for the step.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np
import pybullet as p

log = logging.getLogger(__name__)

PUSH_M = 0.003
"""A touch that moves a plate further than this is a push: closing fingers centre a plate in the
nest's play by up to about 1.6 mm, and a plate set down settles by less."""
BASE_LINK = -1
"""The base, its cover and the hotel's tray are one link in PyBullet: a plate in the hotel rides on it
by design, so its touches are not pushes."""


@dataclass
class _Touch:
    link: str
    start: np.ndarray  # the plate's position when the touch began
    reported: bool = False


@dataclass(frozen=True)
class PlatePush:
    plate: str
    link: str
    moved_m: float
    sim_time: float

    def text(self) -> str:
        return (
            f"{self.link} pushed {self.plate} {self.moved_m * 1000:.1f} mm without holding it "
            f"(t = {self.sim_time:.1f} s)"
        )


class PlatePushWatch:
    """Keeps every push seen (`pushes`) and logs each as it passes PUSH_M."""

    def __init__(self, client: int, link_names: Mapping[int, str], plates: Mapping[str, int]) -> None:
        self.client = client
        self.link_names = dict(link_names)
        self.plates = dict(plates)
        self.plate_of = {body: plate for plate, body in plates.items()}
        self.touches: dict[str, _Touch] = {}
        self.pushes: list[PlatePush] = []

    def check(self, points: Iterable[tuple], held: set[str], sim_time: float) -> None:
        """`points`: the robot's contact points after this step (pybullet's tuples)."""
        touching: dict[str, str] = {}
        for point in points:
            plate = self.plate_of.get(point[2])
            if plate is not None and plate not in held and point[3] != BASE_LINK and point[8] <= 0.0:
                touching.setdefault(plate, self.link_names.get(point[3], f"link {point[3]}"))
        for plate in [plate for plate in self.touches if plate not in touching]:
            del self.touches[plate]  # that touch ended
        for plate, link in touching.items():
            body = self.plates[plate]
            position = np.array(p.getBasePositionAndOrientation(body, physicsClientId=self.client)[0])
            touch = self.touches.setdefault(plate, _Touch(link, position))
            moved = float(np.linalg.norm(position - touch.start))
            if not touch.reported and moved > PUSH_M:
                touch.reported = True
                push = PlatePush(plate, link, moved, sim_time)
                self.pushes.append(push)
                log.warning("plate pushed: %s", push.text())
