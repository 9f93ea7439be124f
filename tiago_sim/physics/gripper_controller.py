"""Parallel gripper: force-capped position control, geared fingers, grasp check and travel attach.

Why: a microplate must be held by friction (16 N per finger, pads and plate at friction 1.0, as
measured in the notes). Only after both pads touch the same plate does a fixed constraint
"attach" it for travel. While it holds, the fingers press with HOLD_SQUEEZE_N only: the attach
stands for the friction of the full grip force, and the full squeeze fighting the (soft) constraint
moved the plate in the hand by up to 1 mm and 0.7 deg between the held-plate measurement above a
nest and the release, and by up to 1.2 mm more while the pads opened (default lab, test_examples,
read from the physics); a corner then met a lead-in ramp (CI). When the fingers open the attach
stays until both pads have left the plate, as the geared fingers of a real gripper leave it
together. The attach holds only what friction could: every step the plate's load is checked
against the grip (grip_load), and a plate asked for more (too little grip force, a heavy plate, a
knock) is let go of; from then on only the friction contacts of the still-closed fingers, pressing
with the full grip force again, hold it, and it slips or falls as physics decides.
Lives on the sim thread.
"""

from __future__ import annotations

import logging

import pybullet as p

from tiago_description import robot_model as rm
from tiago_description.robot_limits import active_limits
from tiago_sim.physics.grip_load import GripLoad, GripLoadMonitor
from tiago_sim.physics.motion import CANCELED, Motion
from tiago_sim.physics.robot_body import RobotBody

log = logging.getLogger(__name__)

PAD_FRICTION = 1.0
PAD_SPINNING_FRICTION = 0.02
STALL_SPEED = 0.002  # m/s: fingers count as stopped below this
STALL_TIME_S = 0.15
ATTACH_FORCE = 60.0  # N: the constraint's own limit; the grip check (grip_load) lets go far below it
HOLDER_FRICTION = 0.15  # the hotel's polished lead-ins, as the station nests' (see scene.NEST_FRICTION)
HOLD_SQUEEZE_N = 2.0  # per finger while attached (the attach stands for the grip force's friction)
GEAR_FORCE = 5.0  # N: keeps the fingers in step in free motion, yields so both pads reach an off-centre plate


class Gripper:
    """One gripper's fingers, its grasp sensing and the travel attach constraint."""

    def __init__(self, body: RobotBody, side: str, plate_bodies: dict[str, int]) -> None:
        self.body = body
        self.side = side
        self.plate_bodies = plate_bodies
        self.fingers = rm.finger_joint_names(side)
        self.finger_links = [body.link_index[f"gripper_{side}_{f}_finger_link"] for f in ("left", "right")]
        self.palm_link, _ = body.frame_on_link(f"gripper_{side}_link")
        self.attach_constraint: int | None = None
        self.attached_id = ""
        self.grip_force_n = rm.FINGER_EFFORT  # per finger; lower it to model a weak grip (tests)
        self.slipped_id = ""  # a plate the attach let go of for overload, until the fingers open
        self.last_slip: GripLoad | None = None
        self._grip_monitor: GripLoadMonitor | None = None
        client = body.client
        for link in self.finger_links:
            p.changeDynamics(
                body.id,
                link,
                lateralFriction=PAD_FRICTION,
                spinningFriction=PAD_SPINNING_FRICTION,
                physicsClientId=client,
            )
        # The hotel tray is merged into the base body (-1). At the default 0.5 a plate released 4 mm
        # off centre stayed on a lead-in chamfer (3 to 5 mm up); at 0.15 it slides into the pocket.
        p.changeDynamics(body.id, -1, lateralFriction=HOLDER_FRICTION, physicsClientId=client)
        left, right = (body.joint_index[n] for n in self.fingers)
        gear = p.createConstraint(
            body.id,
            left,
            body.id,
            right,
            p.JOINT_GEAR,
            [0, 1, 0],
            [0, 0, 0],
            [0, 0, 0],
            physicsClientId=client,
        )
        body.forces.constraint(gear, gearRatio=-1, maxForce=GEAR_FORCE, erp=0.2)
        self.command(rm.FINGER_TRAVEL)

    def command(self, finger_position: float, force_n: float | None = None) -> None:
        """Fingers to ``finger_position`` with ``force_n`` each (default: the grip force)."""
        self.closed = finger_position < rm.FINGER_TRAVEL / 2
        force = self.grip_force_n if force_n is None else force_n
        self.body.command_positions(
            {name: finger_position for name in self.fingers}, force_scale=force / rm.FINGER_EFFORT
        )

    def opening(self) -> float:
        """Gap between the pads in m."""
        joints = self.body.joint_positions()
        return rm.finger_gap(joints[n] for n in self.fingers)

    def holds_by_gap(self) -> bool:
        """What a real gripper's joint states say: commanded closed, and stopped on something."""
        joints = self.body.joint_positions()
        return rm.holds_by_gap(self.closed, (joints[n] for n in self.fingers))

    def _pads_on(self, plate: int) -> list[bool]:
        """Whether each pad touches the plate body ``plate``."""
        client = self.body.client
        return [
            bool(p.getContactPoints(self.body.id, plate, link, -1, physicsClientId=client))
            for link in self.finger_links
        ]

    def touching(self) -> str:
        """Labware id that both pads touch, or ""."""
        for labware_id, plate in self.plate_bodies.items():
            if all(self._pads_on(plate)):
                return labware_id
        return ""

    def attach(self, labware_id: str) -> None:
        """Fix the plate to the palm where it is now (only after a verified friction grasp)."""
        plate = self.plate_bodies[labware_id]
        self.attach_constraint = self.body.fix_to_link(self.palm_link, plate, ATTACH_FORCE)
        self.attached_id = labware_id
        self.command(0.0, HOLD_SQUEEZE_N)
        self._grip_monitor = GripLoadMonitor(
            self.body.client, self.body.id, plate, self.finger_links, self.grip_force_n
        )

    def pads_clear_of(self, labware_id: str) -> bool:
        """Neither pad touches the plate (the opening fingers have left it)."""
        return not any(self._pads_on(self.plate_bodies[labware_id]))

    def start_release(self) -> None:
        """The fingers are about to open: the grip check ends (their force no longer holds the plate by
        design), the attach stays until the pads have left the plate (`GripperMotion`)."""
        self._grip_monitor = None
        self.slipped_id = ""

    def detach(self) -> None:
        """Remove the attach (once the opening pads have left the plate, or when the grip cannot hold
        it)."""
        if self.attach_constraint is not None:
            self.body.forces.remove_constraint(self.attach_constraint)
        self.attach_constraint = None
        self.attached_id = ""
        self._grip_monitor = None

    def check_grip(self, dt: float) -> GripLoad | None:
        """After a physics step: the attached plate's load; lets go of it if friction could not hold it."""
        if self._grip_monitor is None:
            return None
        load = self._grip_monitor.load(dt, self.body.link_pose(f"gripper_{self.side}_grasping_frame"))
        if not load.holds:
            log.warning("%s gripper: %s slips: %s", self.side, self.attached_id, load.describe())
            self.slipped_id, self.last_slip = self.attached_id, load
            self.detach()
            self.command(0.0)  # friction alone holds it now: the full squeeze
        return load

    def loose(self) -> bool:
        """A plate the attach let go of is still between the pads: held by friction contacts alone."""
        return bool(self.slipped_id) and self.touching() == self.slipped_id


class GripperMotion(Motion):
    """Open or close; when closing, ends once the fingers stall (on a plate) or close fully."""

    def __init__(self, gripper: Gripper, close: bool) -> None:
        super().__init__(
            f"gripper_{gripper.side}_{'close' if close else 'open'}", frozenset({f"gripper_{gripper.side}"})
        )
        self.gripper = gripper
        self.close = close
        self.holding = False
        self.opening_m = gripper.opening()
        self.stall_s = 0.0
        self.history: list[list[float]] = []
        self.phase = "closing" if close else "opening"
        if not close:
            gripper.start_release()
        gripper.command(0.0 if close else rm.FINGER_TRAVEL)
        self.remaining_s = rm.FINGER_TRAVEL / active_limits().finger_speed + 0.3

    def tick(self, dt: float) -> None:
        gripper = self.gripper
        self.opening_m = gripper.opening()
        if self.cancel_requested:
            joints = gripper.body.joint_positions()
            gripper.body.command_positions({n: joints[n] for n in gripper.fingers})
            if not self.close:
                gripper.detach()  # the fingers began to open: friction contacts decide from here
            self.finish(False, CANCELED, "canceled")
            return
        if not self.close and gripper.attached_id and gripper.pads_clear_of(gripper.attached_id):
            gripper.detach()  # the plate leaves both pads at once, as from a real gripper's geared fingers
        target = 0.0 if self.close else rm.FINGER_TRAVEL
        remaining = abs(sum(gripper.body.joint_positions()[n] for n in gripper.fingers) / 2 - target)
        self.progress = float(min(0.99, 1.0 - remaining / rm.FINGER_TRAVEL))
        self.remaining_s = remaining / active_limits().finger_speed + 0.2
        # stall from the fingers' travel over the last STALL_TIME_S (reported joint velocities jitter
        # while the gear constraint and the contacts balance)
        positions = [gripper.body.joint_positions()[n] for n in gripper.fingers]
        self.history.append(positions)
        window = max(1, int(STALL_TIME_S / dt))
        del self.history[: -window - 1]
        travel = max(abs(a - b) for a, b in zip(self.history[0], positions, strict=True))
        started = self.elapsed_s > 0.25  # fingers are at rest before they start to move
        moving = len(self.history) <= window or travel > STALL_SPEED * STALL_TIME_S
        self.stall_s = self.stall_s + dt if (started and not moving) else 0.0
        timed_out = (
            self.elapsed_s > rm.FINGER_TRAVEL / active_limits().finger_speed + 1.0
        )  # fingers pressing but jittering
        if remaining < 5e-4 or self.stall_s > 0.0 or timed_out:
            if not self.close:
                gripper.detach()  # open: nothing is held, whatever the contacts say
            else:
                # Holding is what the fingers' gap says, as on a robot; the travel attach (the
                # simulation's stand-in for friction) needs both pads on one plate besides.
                self.holding = gripper.holds_by_gap()
                labware_id = gripper.touching()
                if self.holding and labware_id:
                    gripper.attach(labware_id)
            self.finish(True, message="holding" if self.holding else "")
