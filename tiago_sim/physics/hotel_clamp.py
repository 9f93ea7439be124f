"""The onboard hotel's travel clamp: plates resting in its pockets ride fixed to the base.

Why: a plate that rests in a pocket by contact alone creeps outwards on a turning base, by an
amount that depends on the physics step (0.63 mm per 1.5 rad turn at 1/240 s, 1.25 mm at 1/120 s)
and not on anything a real pocket does. So a turning base with plates aboard had to be simulated
at the short step. Clamped, the base drives at the free-motion step whatever it carries. The
clamp closes on plates already resting in a pocket when a base motion starts and opens once the
base stands again, before any arm reaches in; nothing moves a plate into place, and where a plate
is is still read from physics. Lives on the sim thread.
"""

from __future__ import annotations

import logging

import pybullet as p

from tiago_sim.physics.robot_body import RobotBody

log = logging.getLogger(__name__)

CLAMP_FORCE = 60.0  # N, as the gripper's travel attach


class HotelClamp:
    """Fixed constraints between the hotel tray (merged into the base, link -1) and its plates."""

    def __init__(self, body: RobotBody, plate_bodies: dict[str, int]) -> None:
        self.body = body
        self.plate_bodies = plate_bodies
        self.constraints: dict[str, int] = {}  # labware id -> constraint

    def resting_on_tray(self, exclude: set[str]) -> list[str]:
        """Plates touching the tray that no gripper holds."""
        client = self.body.client
        return [
            labware_id
            for labware_id, plate in self.plate_bodies.items()
            if labware_id not in exclude
            and p.getContactPoints(self.body.id, plate, -1, -1, physicsClientId=client)
        ]

    def close(self, held: set[str]) -> None:
        for labware_id in self.resting_on_tray(held):
            if labware_id not in self.constraints:
                plate = self.plate_bodies[labware_id]
                self.constraints[labware_id] = self.body.fix_to_link(-1, plate, CLAMP_FORCE)
                log.debug("hotel clamp closed on %s", labware_id)

    def open(self, labware_id: str | None = None) -> None:
        """Release one plate, or all of them."""
        for name in [labware_id] if labware_id else list(self.constraints):
            constraint = self.constraints.pop(name, None)
            if constraint is not None:
                p.removeConstraint(constraint, physicsClientId=self.body.client)
                log.debug("hotel clamp opened on %s", name)

    @property
    def closed(self) -> bool:
        return bool(self.constraints)
