"""Motor and constraint force limits kept true when the physics step changes length.

Why: PyBullet turns a motor's or a constraint's force limit into an impulse limit with the step
length current when the limit is set (force times step), and keeps that impulse. The simulation
changes its step between 1/240 s and 1/30 s by situation (simulation.py), so a joint held by a
command given at 1/240 s had an eighth of its effort at 1/30 s: both tucked elbows sank under
gravity onto their 2.36 rad limit on every drive and rose again when the robot stood, a gripper
squeezed with an eighth of its force and an attach held an eighth of its load while the base
drove. Every limit set through here is set again, unchanged in newtons, when the step changes.
Lives on the sim thread.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import pybullet as p


class StepForces:
    """The last force-limited command of every motor and constraint of one PyBullet client."""

    def __init__(self, client: int) -> None:
        self.client = client
        self.motors: dict[tuple[int, int], dict[str, Any]] = {}  # (body, joint) -> its last command
        self.constraints: dict[int, dict[str, Any]] = {}  # constraint id -> changeConstraint's limits

    def position_motor(self, body: int, joint: int, **command: Any) -> None:
        """One joint position-controlled (setJointMotorControl2's keywords), remembered."""
        p.setJointMotorControl2(body, joint, p.POSITION_CONTROL, physicsClientId=self.client, **command)
        self.motors[(body, joint)] = command

    def position_motors(
        self,
        body: int,
        joints: Sequence[int],
        positions: Sequence[float],
        velocities: Sequence[float],
        forces: Sequence[float],
        position_gains: Sequence[float],
        velocity_gains: Sequence[float],
    ) -> None:
        """Several joints in one call (the per-step trajectory tracking), each remembered."""
        p.setJointMotorControlArray(
            body,
            joints,
            p.POSITION_CONTROL,
            targetPositions=positions,
            targetVelocities=velocities,
            forces=forces,
            positionGains=position_gains,
            velocityGains=velocity_gains,
            physicsClientId=self.client,
        )
        motors = self.motors
        for joint, position, velocity, force, kp, kd in zip(
            joints, positions, velocities, forces, position_gains, velocity_gains, strict=True
        ):
            motors[(body, joint)] = {
                "targetPosition": position,
                "targetVelocity": velocity,
                "force": force,
                "positionGain": kp,
                "velocityGain": kd,
            }

    def constraint(self, constraint: int, **limits: Any) -> None:
        """changeConstraint with a force limit (and whatever else it sets), remembered."""
        p.changeConstraint(constraint, physicsClientId=self.client, **limits)
        self.constraints[constraint] = limits

    def remove_constraint(self, constraint: int) -> None:
        p.removeConstraint(constraint, physicsClientId=self.client)
        self.constraints.pop(constraint, None)

    def restate(self) -> None:
        """After a change of the step length: every limit again, in newtons at the new step."""
        for (body, joint), command in self.motors.items():
            p.setJointMotorControl2(body, joint, p.POSITION_CONTROL, physicsClientId=self.client, **command)
        for constraint, limits in self.constraints.items():
            p.changeConstraint(constraint, physicsClientId=self.client, **limits)
