"""Is a plate near something that may touch it? Decides when the simulation needs its short step.

Why: the physics step is long (1/60 s) in free motion and short (1/240 s) whenever a contact with
a plate may start (simulation.py, "Physics step"): a moving robot link near a resting plate, or a
held plate near anything but its own arm. Lives on the sim thread (it queries the client).
"""

from __future__ import annotations

import numpy as np
import pybullet as p

from tiago_description import robot_model as rm
from tiago_sim.physics.gripper_controller import Gripper
from tiago_sim.physics.robot_body import RobotBody

STEP_REVIEW_PERIOD = 0.05  # s of sim time between proximity checks (tool <= 1.5 m/s: 7.5 cm)
# A contact may start soon when two things are closer than this margin plus twice the distance the
# faster one travels in a review period at its current speed (it cannot get there unnoticed): a
# robot link and a plate no gripper holds (the link's point nearest the plate, the plate resting),
# or a held plate and anything but its own arm. Before, a robot link within a fixed 0.15 m of a
# resting plate kept the steps short: 1695 of a transfer's 2900 short steps, most of
# them with the tool still 4 to 15 cm away at its 0.08 m/s.
CONTACT_MARGIN = 0.03  # m
MAX_LINK_SPEED = 1.5  # m/s: no robot link moves faster (arm joint limits); bounds the query radius
QUERY_RANGE = CONTACT_MARGIN + 2.0 * MAX_LINK_SPEED * STEP_REVIEW_PERIOD


def _reach(speed: float) -> float:
    return CONTACT_MARGIN + 2.0 * speed * STEP_REVIEW_PERIOD


class PlateProximity:
    """Proximity queries between the robot, the plates and everything else."""

    def __init__(
        self, client: int, robot: RobotBody, plates: dict[str, int], grippers: dict[str, Gripper]
    ) -> None:
        self.client = client
        self.robot = robot
        self.plates = plates
        self.grippers = grippers
        self.own_arm_links = {
            side: {
                index
                for name, index in robot.link_index.items()
                if name.startswith((f"arm_{side}_", f"gripper_{side}_"))
            }
            for side in rm.ARM_SIDES
        }

    def plate_within_range(self, held: set[str]) -> bool:
        return self.robot_near_resting_plate(held) or self.held_plate_near_anything()

    def robot_near_resting_plate(self, held: set[str]) -> bool:
        """A robot link other than the base (its hotel tray carries plates) within reach of a plate
        no gripper holds."""
        nearest: dict[int, tuple] = {}  # robot link -> its closest point to any resting plate
        for labware_id, plate in self.plates.items():
            if labware_id in held:
                continue
            for point in p.getClosestPoints(self.robot.id, plate, QUERY_RANGE, physicsClientId=self.client):
                link = point[3]
                if link != -1 and (link not in nearest or point[8] < nearest[link][8]):
                    nearest[link] = point
        return any(
            point[8] < CONTACT_MARGIN or point[8] < _reach(self._point_speed(link, point[5]))
            for link, point in nearest.items()
        )

    def _point_speed(self, link: int, point: tuple[float, float, float]) -> float:
        """Speed of a point fixed to a robot link (its centre of mass moves and it turns)."""
        state = p.getLinkState(self.robot.id, link, computeLinkVelocity=1, physicsClientId=self.client)
        lever = np.subtract(point, state[0])
        return float(np.linalg.norm(np.add(state[6], np.cross(state[7], lever))))

    def held_plate_near_anything(self) -> bool:
        """A held plate within reach of a body, or of a robot link other than its own arm's."""
        c = self.client
        for side, gripper in self.grippers.items():
            if not gripper.attached_id:
                continue
            plate = self.plates[gripper.attached_id]
            speed = float(np.linalg.norm(p.getBaseVelocity(plate, physicsClientId=c)[0]))
            reach = _reach(speed)
            own_links = self.own_arm_links[side]
            for index in range(p.getNumBodies(physicsClientId=c)):
                other = p.getBodyUniqueId(index, physicsClientId=c)
                if other == plate:
                    continue
                for point in p.getClosestPoints(plate, other, reach, physicsClientId=c):
                    if other != self.robot.id or point[4] not in own_links:
                        return True
        return False
