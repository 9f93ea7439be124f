"""What a held plate asks of the pads' friction, and whether friction could give it.

Why: after a verified friction grasp the gripper fixes the plate to the palm with a constraint (the
travel attach; see gripper_controller), because a PyBullet friction grasp slips a little at every
step. A constraint alone would hold any plate against any load, so "no plate lost in carry" would
hold by construction. So at every physics step the load the grip must carry is worked out from the
plate's motion and contacts, and checked against what Coulomb friction at the two pads could hold:

- The grip must supply F = m (a - g) - F_ext: the plate's weight and inertia (``a`` from the change
  of its velocity over the step) less what anything but the two finger pads pushes on it (a nest
  floor under it carries part of its weight; a table edge that knocks it adds a load). Contacts
  count by their normal forces only (friction between plate and holder is small: 0.15 on lead-ins).
- In the pad plane (perpendicular to the closing axis) the pads hold ``2 mu F_N`` (two pads, each
  pressed with the finger force F_N; mu the pad-plate pair's friction, which PyBullet takes as the
  product of the two bodies' coefficients).
- About the closing axis they hold a twist of ``2 F_N s``, with ``s`` the pad-plate pair's
  torsional friction as PyBullet combines it for the simulated contacts (spinning friction of one
  body times the other's friction, both ways: 0.02 x 1.0 + 0.02 x 1.0 = 0.04 m), so the attach
  holds no more than the simulated friction contacts would, and a plate let go of slips no sooner
  than it would have. That limit (1.28 N m at 16 N) is generous: uniform pressure on a strip as
  long as the pad is wide (80 mm) gives a mean lever arm of L / 4 = 20 mm, 0.64 N m at mu 1; with
  that value 6 of 30 scripted placements into the hotel pocket under the default calibration errors
  let go of the plate as a corner met a lead-in, against none at 0.04 m.
  The twist the grip must hold is the moment of the loads above about the grasping frame (the
  plate's rotational inertia, 7e-4 kg m^2, is left out: at the arm's angular accelerations it is
  under 1 % of the capacity).

On the step where the physics step changes length (simulation.py's regimes) the acceleration is
left out: PyBullet's position control corrects a joint's tracking error by a fraction per step, so
a shorter step corrects it faster and the arm's (and the held plate's) velocity jumps within one
short step. That jump is the simulator's discretisation, not a load: it let go of a deep-well plate
as it neared the hotel pocket (28.5 N against the 28.0 N the friction holds, at the first
1/240 s step after 1/60 s steps, nothing but the fingers touching it), and the plate, loose in the
pocket, was later placed beside the nest. Weight and contacts still count on that step.

Along the closing axis the fingers' own motors resist, so that direction is not checked. A load
beyond either limit means the plate would slip: the caller lets go of the constraint and from then
on only the simulated friction contacts hold the plate, as on the real robot. Lives on the sim thread.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pybullet as p

GRAVITY = np.array([0.0, 0.0, -9.81])


@dataclass(frozen=True)
class GripLoad:
    """One step's demand on the grip against its capacity (N, N m)."""

    in_plane_n: float
    twist_nm: float
    in_plane_capacity_n: float
    twist_capacity_nm: float
    largest_push: tuple[int, int, float] = (-1, -1, 0.0)  # (body, link, N) of the hardest contact

    @property
    def holds(self) -> bool:
        return self.in_plane_n <= self.in_plane_capacity_n and self.twist_nm <= self.twist_capacity_nm

    def describe(self) -> str:
        return (
            f"load {self.in_plane_n:.1f} N in the pad plane "
            f"(friction holds {self.in_plane_capacity_n:.1f} N), "
            f"twist {self.twist_nm:.3f} N m (holds {self.twist_capacity_nm:.3f} N m)"
            + (
                f"; pushed hardest by body {self.largest_push[0]} link {self.largest_push[1]} "
                f"with {self.largest_push[2]:.1f} N"
                if self.largest_push[2] > 0
                else ""
            )
        )


class GripLoadMonitor:
    """Follows one held plate from step to step (its velocity change gives its acceleration)."""

    def __init__(
        self, client: int, robot_id: int, plate: int, finger_links: list[int], grip_force_n: float
    ) -> None:
        self.client = client
        self.robot_id = robot_id
        self.plate = plate
        self.finger_links = set(finger_links)
        plate_info = p.getDynamicsInfo(plate, -1, physicsClientId=client)
        pad_info = p.getDynamicsInfo(robot_id, finger_links[0], physicsClientId=client)
        self.mass = float(plate_info[0])
        # PyBullet's combination rules (btManifoldResult): friction multiplies; torsional friction is
        # one body's spinning friction times the other's friction, summed both ways.
        friction = plate_info[1] * pad_info[1]
        torsion_m = plate_info[7] * pad_info[1] + pad_info[7] * plate_info[1]
        self.in_plane_capacity_n = 2.0 * friction * grip_force_n
        self.twist_capacity_nm = 2.0 * torsion_m * grip_force_n
        self._velocity: np.ndarray | None = None
        self._step_s: float | None = None

    def load(self, dt: float, T_world_grasp: np.ndarray) -> GripLoad:
        """The load of the step just taken (call once after every physics step while held)."""
        c = self.client
        velocity = np.array(p.getBaseVelocity(self.plate, physicsClientId=c)[0])
        step_changed = self._step_s is not None and abs(dt - self._step_s) > 1e-9
        if self._velocity is None or dt <= 0 or step_changed:
            acceleration = np.zeros(3)
        else:
            acceleration = (velocity - self._velocity) / dt
        self._velocity, self._step_s = velocity, dt
        centre = np.array(p.getBasePositionAndOrientation(self.plate, physicsClientId=c)[0])
        grip_centre = T_world_grasp[:3, 3]
        closing_axis = T_world_grasp[:3, 1]
        inertial = self.mass * (acceleration - GRAVITY)  # what the supports together must supply
        force = inertial.copy()
        moment = np.cross(centre - grip_centre, inertial)
        largest = (-1, -1, 0.0)
        for point in p.getContactPoints(bodyA=self.plate, physicsClientId=c):
            if point[2] == self.robot_id and point[4] in self.finger_links:
                continue
            push = point[9] * np.asarray(point[7])  # on the plate, along the normal from the other body
            force -= push
            moment -= np.cross(np.asarray(point[5]) - grip_centre, push)
            if point[9] > largest[2]:
                largest = (point[2], point[4], float(point[9]))
        along_axis = float(force @ closing_axis)
        in_plane = math.sqrt(max(0.0, float(force @ force) - along_axis * along_axis))
        twist = abs(float(moment @ closing_axis))
        return GripLoad(in_plane, twist, self.in_plane_capacity_n, self.twist_capacity_nm, largest)
