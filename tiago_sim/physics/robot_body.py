"""The robot as a PyBullet multibody: name lookups, joint readings and motor commands.

Why: controllers speak URDF joint names; this is the one place that maps them to PyBullet
indices. The base is carried by a fixed constraint whose pivot follows the commanded planar
motion (see base_controller).

Joint readings and position commands are in encoder terms: with ``encoder_offsets`` set (a joint
calibration error, see tiago_sim.measuring.disturbances) a joint reads its true angle plus its
offset, and a commanded position puts the true joint at the command minus the offset, as on a
robot whose encoder zeros are off. Everything above this class (controllers, IK, the robot
software) sees only encoder values; link poses (rendering, physics) stay true. Lives on the sim thread.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
from functools import lru_cache

import numpy as np
import pinocchio as pin
import pybullet as p

from tiago_description import robot_model
from tiago_description import transforms as tf
from tiago_description.robot_limits import active_limits
from tiago_sim.physics.step_forces import StepForces

BASE_CONSTRAINT_FORCE = 1e5
ARM_POSITION_GAIN = 0.3


ROBOT_COLLISION_GROUP = 0x40
"""The robot's links' collision group: none of Bullet's own (default 1, static 2), so a ray test
with the mask ``~ROBOT_COLLISION_GROUP`` passes through the robot. Its mask stays "everything": the
robot touches the lab and the plates exactly as with Bullet's default groups."""


class RobotBody:
    """Loads the generated URDF at a floor pose and offers name-based access."""

    def __init__(self, client: int, T_world_base: np.ndarray) -> None:
        self.client = client
        self.forces = StepForces(client)  # every force limit, set again when the step changes
        position, quat = tf.to_pose(T_world_base)
        # Fixed links are merged into their moving parent (half the links, twice the speed); their
        # frames stay reachable through ``frame_offsets`` (moving link, T_link_frame) from the URDF.
        with _quiet_stdout():
            self.id = p.loadURDF(
                str(robot_model.urdf_path()),
                position.tolist(),
                quat.tolist(),
                flags=p.URDF_USE_INERTIA_FROM_FILE | p.URDF_MERGE_FIXED_LINKS,
                physicsClientId=client,
            )
        self.joint_index: dict[str, int] = {}
        self.link_index: dict[str, int] = {"base_footprint": -1}
        self.limits: dict[str, tuple[float, float, float, float]] = {}  # lower, upper, velocity, effort
        for index in range(p.getNumJoints(self.id, physicsClientId=client)):
            info = p.getJointInfo(self.id, index, physicsClientId=client)
            name, kind = info[1].decode(), info[2]
            self.link_index[info[12].decode()] = index
            if kind != p.JOINT_FIXED:
                self.joint_index[name] = index
                # the velocity the controllers hold it to: the lab's limit, within the URDF's (hardware)
                velocity = active_limits().joint_velocity.get(name, info[11])
                self.limits[name] = (info[8], info[9], velocity, info[10])
        # no default velocity motors fighting our controllers; hold every joint where it is
        for index in self.joint_index.values():
            p.setJointMotorControl2(self.id, index, p.VELOCITY_CONTROL, force=0.0, physicsClientId=client)
        # PyBullet's base frame is the merged base's centre of mass, not base_footprint
        inertial = p.getDynamicsInfo(self.id, -1, physicsClientId=client)
        self.T_com_footprint = tf.invert(tf.from_pose(inertial[3], inertial[4]))
        offset_position, offset_quat = tf.to_pose(self.T_com_footprint)
        self._footprint_in_com = (
            float(self.T_com_footprint[0, 3]),
            float(self.T_com_footprint[1, 3]),
            float(math.atan2(self.T_com_footprint[1, 0], self.T_com_footprint[0, 0])),
        )
        self.base_constraint = p.createConstraint(
            self.id,
            -1,
            -1,
            -1,
            p.JOINT_FIXED,
            [0, 0, 0],
            offset_position.tolist(),
            position.tolist(),
            parentFrameOrientation=offset_quat.tolist(),
            childFrameOrientation=quat.tolist(),
            physicsClientId=client,
        )
        self.forces.constraint(self.base_constraint, maxForce=BASE_CONSTRAINT_FORCE)
        # every link in a collision group of its own, colliding with everything as before, so that
        # ray tests can leave the robot out (the base laser never sees it)
        for link in self.link_index.values():
            p.setCollisionFilterGroupMask(self.id, link, ROBOT_COLLISION_GROUP, -1, physicsClientId=client)
        self.targets: dict[str, float] = {}  # commanded, in encoder terms
        self.encoder_offsets: dict[str, float] = {}  # joint name -> reading minus true position
        self._track_groups: dict[tuple[str, ...], tuple] = {}
        self.frame_offsets = _fixed_frame_offsets()

    def reset_posture(self, torso_lift: float, arm_positions: tuple[float, ...]) -> None:
        """Initial configuration before any physics step: both arms at ``arm_positions`` (right-arm
        joint order; the left arm mirrors it), fingers open, head level, torso at ``torso_lift``;
        the motors hold it."""
        posture = {"torso_lift_joint": torso_lift}
        for side in robot_model.ARM_SIDES:
            posture.update(dict(zip(robot_model.arm_joint_names(side), arm_positions, strict=True)))
            posture.update({name: robot_model.FINGER_TRAVEL for name in robot_model.finger_joint_names(side)})
        for name, value in posture.items():
            p.resetJointState(self.id, self.joint_index[name], value, physicsClientId=self.client)
        hold = {n: v for n, v in posture.items() if "finger" not in n}
        hold.update({"head_1_joint": 0.0, "head_2_joint": 0.0})
        self.command_positions(hold)

    def set_base_target(self, x: float, y: float, yaw: float) -> None:
        quat = [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)]
        p.changeConstraint(
            self.base_constraint,
            jointChildPivot=[x, y, 0.0],
            jointChildFrameOrientation=quat,
            maxForce=BASE_CONSTRAINT_FORCE,
            physicsClientId=self.client,
        )

    def base_xy_yaw(self) -> tuple[float, float, float]:
        """Ground-truth planar pose of base_footprint (cheap: for the per-step encoder model)."""
        (px, py, _), (qx, qy, qz, qw) = p.getBasePositionAndOrientation(self.id, physicsClientId=self.client)
        yaw = math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
        ox, oy, oyaw = self._footprint_in_com
        c, s = math.cos(yaw), math.sin(yaw)
        return px + c * ox - s * oy, py + s * ox + c * oy, yaw + oyaw

    def base_pose(self) -> np.ndarray:
        """Ground-truth T_world_base (for the controllers' actuator model and success checks only)."""
        position, quat = p.getBasePositionAndOrientation(self.id, physicsClientId=self.client)
        return tf.from_pose(position, quat) @ self.T_com_footprint

    def base_twist(self) -> tuple[float, float]:
        """Forward speed and yaw rate of the base (what the wheel encoders see)."""
        linear, angular = p.getBaseVelocity(self.id, physicsClientId=self.client)
        _, (qx, qy, qz, qw) = p.getBasePositionAndOrientation(self.id, physicsClientId=self.client)
        yaw = math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
        # velocity of the footprint origin = centre-of-mass velocity + w x (origin - com), planar part
        dx = self.T_com_footprint[0, 3] * math.cos(yaw) - self.T_com_footprint[1, 3] * math.sin(yaw)
        dy = self.T_com_footprint[0, 3] * math.sin(yaw) + self.T_com_footprint[1, 3] * math.cos(yaw)
        vx = linear[0] - angular[2] * dy
        vy = linear[1] + angular[2] * dx
        return vx * math.cos(yaw) + vy * math.sin(yaw), angular[2]

    def joint_positions(self) -> dict[str, float]:
        """Encoder readings: the true positions plus ``encoder_offsets``."""
        names = list(self.joint_index)
        states = p.getJointStates(self.id, [self.joint_index[n] for n in names], physicsClientId=self.client)
        offsets = self.encoder_offsets
        return {n: float(state[0]) + offsets.get(n, 0.0) for n, state in zip(names, states, strict=True)}

    def set_encoder_offsets(self, offsets: dict[str, float]) -> None:
        """Joint calibration errors (rad or m); the true posture stays, its readings change."""
        unknown = set(offsets) - set(self.joint_index)
        if unknown:
            raise KeyError(f"unknown joints: {sorted(unknown)}")
        old = self.encoder_offsets
        self.targets = {n: v - old.get(n, 0.0) + offsets.get(n, 0.0) for n, v in self.targets.items()}
        self.encoder_offsets = dict(offsets)
        self._track_groups.clear()

    def joint_velocities(self, names: list[str]) -> np.ndarray:
        states = p.getJointStates(self.id, [self.joint_index[n] for n in names], physicsClientId=self.client)
        return np.array([state[1] for state in states])

    def command_positions(
        self, targets: dict[str, float], velocities: dict[str, float] | None = None, force_scale: float = 1.0
    ) -> None:
        """Position-control the named joints within their URDF effort and velocity limits."""
        for name, commanded in targets.items():
            lower, upper, velocity_limit, effort = self.limits[name]
            offset = self.encoder_offsets.get(name, 0.0)
            target = float(commanded) - offset  # the true position the motor drives to
            target = min(max(target, lower), upper) if upper > lower else target
            self.targets[name] = target + offset
            self.forces.position_motor(
                self.id,
                self.joint_index[name],
                targetPosition=target,
                targetVelocity=(velocities or {}).get(name, 0.0),
                force=effort * force_scale,
                maxVelocity=velocity_limit,
                positionGain=ARM_POSITION_GAIN,
                velocityGain=1.0,
            )

    def track(self, names: list[str], positions: np.ndarray, velocities: np.ndarray) -> None:
        """Per-step trajectory tracking in one call (targets already timed within the velocity limits)."""
        key = tuple(names)
        group = self._track_groups.get(key)
        if group is None:  # per joint group, built once: this runs at every physics step of a motion
            lower = np.array(
                [self.limits[n][0] if self.limits[n][1] > self.limits[n][0] else -np.inf for n in names]
            )
            upper = np.array(
                [self.limits[n][1] if self.limits[n][1] > self.limits[n][0] else np.inf for n in names]
            )
            group = (
                [self.joint_index[n] for n in names],
                lower,
                upper,
                [self.limits[n][3] for n in names],
                [ARM_POSITION_GAIN] * len(names),
                [1.0] * len(names),
                np.array([self.encoder_offsets.get(n, 0.0) for n in names]),
            )
            self._track_groups[key] = group
        indices, lower, upper, forces, position_gains, velocity_gains, offsets = group
        clipped = np.minimum(np.maximum(np.asarray(positions) - offsets, lower), upper)
        self.targets.update(zip(names, (clipped + offsets).tolist(), strict=True))
        clipped = clipped.tolist()
        self.forces.position_motors(
            self.id,
            indices,
            clipped,
            np.asarray(velocities, dtype=float).tolist(),
            forces,
            position_gains,
            velocity_gains,
        )

    def link_pose(self, link: str) -> np.ndarray:
        """Ground-truth T_world_link of a link frame (for rendering and checks, not for robot software)."""
        offset = np.eye(4)
        if link not in self.link_index:
            link, offset = self.frame_offsets[link]
        index = self.link_index[link]
        if index < 0:
            return self.base_pose() @ offset
        state = p.getLinkState(self.id, index, computeForwardKinematics=True, physicsClientId=self.client)
        return tf.from_pose(state[4], state[5]) @ offset

    def fix_to_link(self, link: int, body: int, max_force: float) -> int:
        """A fixed constraint holding ``body`` to ``link`` (-1: the base) where it is now, no jump.

        Constraint frames are relative to the link's centre of mass frame, which getLinkState's
        [0:2] and getBasePositionAndOrientation give in world.
        """
        client = self.client
        if link < 0:
            link_position, link_quat = p.getBasePositionAndOrientation(self.id, physicsClientId=client)
        else:
            state = p.getLinkState(self.id, link, computeForwardKinematics=True, physicsClientId=client)
            link_position, link_quat = state[0], state[1]
        body_position, body_quat = p.getBasePositionAndOrientation(body, physicsClientId=client)
        inv_position, inv_quat = p.invertTransform(link_position, link_quat)
        parent_position, parent_quat = p.multiplyTransforms(inv_position, inv_quat, body_position, body_quat)
        constraint = p.createConstraint(
            self.id,
            link,
            body,
            -1,
            p.JOINT_FIXED,
            [0, 0, 0],
            parent_position,
            [0, 0, 0],
            parentFrameOrientation=parent_quat,
            physicsClientId=client,
        )
        self.forces.constraint(constraint, maxForce=max_force)
        return constraint

    def frame_on_link(self, frame: str) -> tuple[int, np.ndarray]:
        """(PyBullet link index, T_link_frame) of any URDF link, merged or not."""
        if frame in self.link_index:
            return self.link_index[frame], np.eye(4)
        link, offset = self.frame_offsets[frame]
        return self.link_index[link], offset


@contextlib.contextmanager
def _quiet_stdout():
    """PyBullet's URDF merger prints every merged link from C; keep test and node logs clean."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as devnull:
        os.dup2(devnull.fileno(), 1)
    try:
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


@lru_cache(maxsize=1)
def _fixed_frame_offsets() -> dict[str, tuple[str, np.ndarray]]:
    """For every URDF link: (the link that carries it after merging, T_thatlink_link), via pinocchio."""
    model = pin.buildModelFromUrdf(str(robot_model.urdf_path()))
    offsets: dict[str, tuple[str, np.ndarray]] = {}
    for frame in model.frames:
        if frame.type != pin.FrameType.BODY:
            continue
        joint_id = frame.parentJoint
        carrier = "base_footprint" if joint_id == 0 else _child_link_of(model, joint_id)
        offsets[frame.name] = (carrier, frame.placement.homogeneous.copy())
    return offsets


def _child_link_of(model: pin.Model, joint_id: int) -> str:
    for frame in model.frames:
        if (
            frame.type == pin.FrameType.BODY
            and frame.parentJoint == joint_id
            and frame.placement.isIdentity()
        ):
            return frame.name
    raise KeyError(f"no link on joint {model.names[joint_id]}")
