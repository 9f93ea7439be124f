"""The onboard hotel's travel clamp: plates resting in its pockets ride fixed to the base.

Why: a plate that rests in a pocket by contact alone creeps outwards on a turning base, by an
amount that depends on the physics step (0.63 mm per 1.5 rad turn at 1/240 s, 1.25 mm at 1/120 s)
and not on anything a real pocket does. So a turning base with plates aboard had to be simulated
at the short step. Clamped, the base drives at the free-motion step whatever it carries. The
clamp closes on plates already resting in a pocket when a base motion starts and opens once the
base stands again, before any arm reaches in; nothing moves a plate into place, and where a plate
is is still read from physics.

The clamp stands in for the pocket only against the base's own motion (the pocket's walls and floor
hold a plate through the base's accelerations and turns). Anything else that pushes on a clamped
plate (a table edge the tray sweeps into, an arm) opens the clamp on it at once if the push exceeds
what the plate's weight presses into the pocket floor's friction (about 0.5 N for a 0.35 kg plate):
from then on its contacts alone decide whether it stays. Lives on the sim thread.
"""

from __future__ import annotations

import logging

import pybullet as p

from tiago_sim.physics.robot_body import RobotBody

log = logging.getLogger(__name__)

CLAMP_FORCE = 60.0  # N, as the gripper's travel attach
GRAVITY = 9.81


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
                self.body.forces.remove_constraint(constraint)
                log.debug("hotel clamp opened on %s", name)

    def release_pushed(self, friction: float) -> list[str]:
        """After a physics step: open the clamp on every plate something else pushes harder than
        ``friction`` times its weight; returns their ids."""
        client = self.body.client
        released = []
        for labware_id in list(self.constraints):
            plate = self.plate_bodies[labware_id]
            limit = friction * GRAVITY * p.getDynamicsInfo(plate, -1, physicsClientId=client)[0]
            push = max(
                (
                    point[9]
                    for point in p.getContactPoints(bodyA=plate, physicsClientId=client)
                    if not (point[2] == self.body.id and point[4] == -1)  # the tray itself
                ),
                default=0.0,
            )
            if push > limit:
                log.warning("hotel clamp opens on %s: pushed with %.1f N (limit %.2f N)", labware_id, push,
                            limit)  # fmt: skip
                self.open(labware_id)
                released.append(labware_id)
        return released

    @property
    def closed(self) -> bool:
        return bool(self.constraints)
