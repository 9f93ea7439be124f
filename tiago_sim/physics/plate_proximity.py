"""Is a plate near something that may touch it? Decides when the simulation needs its short step.

Why: the physics step is long (1/60 s) in free motion and short (1/240 s) whenever a contact with
a plate may start (simulation.py, "Physics step"): a moving robot link near a resting plate, or a
held plate near anything but its own arm. Lives on the sim thread (it queries the client).
"""

from __future__ import annotations

import numpy as np
import pybullet as p

from tiago_sim.physics.gripper_controller import Gripper
from tiago_sim.physics.robot_body import RobotBody
from tiago_sim.robot import robot_model as rm

PLATE_NEAR_RANGE = 0.15  # m between a moving robot link and a plate: a finger contact may start soon
STEP_REVIEW_PERIOD = 0.05  # s of sim time between proximity checks (tool <= 1.5 m/s: 7.5 cm)
# A held plate is within reach of something when it is closer than this margin plus twice the
# distance it travels in a review period at its current speed (it cannot get there unnoticed).
HELD_PLATE_MARGIN = 0.03  # m


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
        """A robot link other than the base (its hotel tray carries plates) near a plate no gripper holds."""
        return any(
            point[3] != -1
            for labware_id, plate in self.plates.items()
            if labware_id not in held
            for point in p.getClosestPoints(
                self.robot.id, plate, PLATE_NEAR_RANGE, physicsClientId=self.client
            )
        )

    def held_plate_near_anything(self) -> bool:
        """A held plate within reach of a body, or of a robot link other than its own arm's."""
        c = self.client
        for side, gripper in self.grippers.items():
            if not gripper.attached_id:
                continue
            plate = self.plates[gripper.attached_id]
            speed = float(np.linalg.norm(p.getBaseVelocity(plate, physicsClientId=c)[0]))
            reach = HELD_PLATE_MARGIN + 2.0 * speed * STEP_REVIEW_PERIOD
            own_links = self.own_arm_links[side]
            for index in range(p.getNumBodies(physicsClientId=c)):
                other = p.getBodyUniqueId(index, physicsClientId=c)
                if other == plate:
                    continue
                for point in p.getClosestPoints(plate, other, reach, physicsClientId=c):
                    if other != self.robot.id or point[4] not in own_links:
                        return True
        return False
