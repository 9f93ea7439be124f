"""The simulated TIAGo++ in its lab: the Simulation API the ROS node calls (see the module contract).

Why one class: it owns the PyBullet client (DIRECT, fixed step) and is the only place where
physics advances; motions are started by methods that return a Motion at once and run as step()
is called. Sensors report what the robot could know (odometry, joint encoders, dock contact,
gripper contact); ``check_placement`` is ground truth for success checks only.
Lives on one thread (the sim thread): every method must be called there.
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np
import pybullet as p

from lab_description.world import World
from labware_model.holders import Nest
from labware_model.readings import HotelSlotReading, NestReading, PlacementCheck
from robot_port.types import CameraIntrinsics, JointTrajectory, joint_group
from tiago_description import robot_model as rm
from tiago_sim.navigation.blockage import UnmappedObstacles
from tiago_sim.navigation.planner import Plan
from tiago_sim.physics.arm_controller import JointTrajectoryMotion, TimedTrajectoryMotion
from tiago_sim.physics.base_controller import DiffDriveBase, DriveMotion, VelocityMotion, docking_motion
from tiago_sim.physics.base_laser import BaseLaser, LaserSpec, laser_rng
from tiago_sim.physics.camera import render_rgbd
from tiago_sim.physics.collision_watch import COLLISION, CollisionWatch
from tiago_sim.physics.gripper_controller import HOLDER_FRICTION, Gripper, GripperMotion
from tiago_sim.physics.guarded_path import GuardedPathMotion
from tiago_sim.physics.hotel_clamp import HotelClamp
from tiago_sim.physics.motion import BUSY, CompletedMotion, FailedMotion, Motion
from tiago_sim.physics.path_following import path_motion
from tiago_sim.physics.plate_proximity import STEP_REVIEW_PERIOD, PlateProximity
from tiago_sim.physics.plate_pushes import PlatePushWatch
from tiago_sim.physics.plate_sensing import PlateSensing
from tiago_sim.physics.robot_body import RobotBody
from tiago_sim.physics.scene import build_scene
from tiago_sim.physics.sim_clock import SimClock
from tiago_sim.physics.step_ledger import StepLedger

log = logging.getLogger(__name__)

# Solver iterations by situation: the notes' 150 while fingers close or open on a plate; 20 otherwise
# (joint tracking error stays under 1 mrad). A plate held by a gripper or riding the hotel is fixed
# by a constraint (the travel attach, the hotel clamp), so it needs no more: at 20 instead of 30
# the physics of a benchmark transfer took 3.8 instead of 4.8 s CPU and the placement error stayed
# at 1.0 to 1.6 mm (seeds 1 to 3).
SOLVER_ITERATIONS_GRASPING = 150
SOLVER_ITERATIONS = 20
# Physics step: the notes' 1/240 s whenever a gripper moves, or a moving link (arm, torso, head)
# comes within reach of a plate resting anywhere (plate_proximity.py), or a held plate comes within reach of
# anything but its own arm (grasp, place, release, into and out of the hotel); FREE_MOTION_STEP_RATIO
# times that otherwise (free arm moves, carrying through free space; driving: below), where only joint
# tracking, the kinematic base and constrained plates are simulated. The long step is the largest
# saving of wall time per simulated second: 1/60 s halved the steps of the free phases against
# 1/120 s (a benchmark transfer: 2230 instead of 4260 steps, 0.6 s CPU less) with the marker-guided
# alignment, the placement and the docking as accurate as before. A plate resting in the hotel by
# contact alone used to keep the steps short while the base turned (it crept outwards per step on
# the curved path); the hotel clamp now holds it while the base moves.
FREE_MOTION_STEP_RATIO = 4
# Only the base driving (no other motion, no plate in reach): twice as long, half of a transfer's
# simulated time (the sim thread's CPU in motion fell by a fifth). Not for arm motions: at 1/30 s
# the wrists missed SETTLE_TOLERANCE by 3 to 11 mrad (7 of 8 transfers failed).
DRIVE_STEP_RATIO = 8
# Error reduction of joint constraints (the base carrier) per step: Bullet's 0.2 at 1/240 s, 0.5 at
# the long step, so that the base lags its commanded pose by the same 17 ms at either step (about
# step * (1 - erp) / erp; measured at 0.27 and 0.53 m/s: 16.7 ms at 1/240 s and 0.2, 20.4 ms at
# 1/60 s and 0.45, 11.1 ms at 1/60 s and 0.6).
CONSTRAINT_ERP = 0.2
FREE_MOTION_CONSTRAINT_ERP = 0.5
DRIVE_CONSTRAINT_ERP = 0.66  # the same lag at 1/30 s: 17.2 ms at 0.27 and 0.53 m/s
LOADED_TURN_RATE = 0.05  # rad/s: above it, with an unclamped plate in the hotel, steps stay short
DOCK_SENSOR_RANGE = 0.004  # m: the charging contacts close within this distance
# The start posture: arms folded (as in "Travel"), head level; not PAL's `home` (other values).
START_ARM = (0.2, -1.1, -0.2, 1.94, -1.57, 1.37, 0.0)
START_TORSO = 0.15


class Simulation:
    """PyBullet world + robot; see the module docstring for threading."""

    def __init__(
        self,
        world: World,
        *,
        seed: int | None = None,
        time_step: float = 1 / 240,
        odometry_noise: float = 0.0005,
    ) -> None:
        self.world = world
        self.time_step = time_step
        self.sim_time = 0.0
        self.rng = np.random.default_rng(seed)
        self.client_id = p.connect(p.DIRECT)
        c = self.client_id
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        p.setPhysicsEngineParameter(
            fixedTimeStep=time_step,
            numSolverIterations=SOLVER_ITERATIONS,
            erp=CONSTRAINT_ERP,
            physicsClientId=c,
        )
        self.robot = RobotBody(c, world.dock_pose.matrix())
        self.robot.reset_posture(START_TORSO, START_ARM)
        self.T_world_slot_at_start = {
            i: self.robot.link_pose(f"hotel_slot_{i}") for i in range(1, world.hotel_slots + 1)
        }
        self.scene = build_scene(c, world, self.T_world_slot_at_start)
        dock = world.dock_pose
        self.base = DiffDriveBase(self.robot, dock.x, dock.y, dock.yaw, odometry_noise, self.rng)
        self.laser = BaseLaser(c, self.robot, LaserSpec(), laser_rng(seed))
        self.clock = SimClock()  # sensors and robot software at fixed simulated rates
        self.grippers = {side: Gripper(self.robot, side, self.scene.plates) for side in rm.ARM_SIDES}
        self.hotel_clamp = HotelClamp(self.robot, self.scene.plates)
        self._clamped_for_drive = False
        self.plate_proximity = PlateProximity(c, self.robot, self.scene.plates, self.grippers)
        # The head camera's true mount against the model's head_front_camera_rgb_optical_frame (a hand-eye
        # calibration error; identity unless tiago_sim.measuring.disturbances sets one).
        self.T_camera_mount_error = np.eye(4)
        self.motions: list[Motion] = []
        self._iterations = SOLVER_ITERATIONS
        self._step = time_step
        self.last_step_s = time_step  # length of the latest physics step (s)
        self.step_ledger = StepLedger()
        self.plate_sensing = PlateSensing(c, world, self.robot, self.scene, self.grippers)
        self.collision_watch = CollisionWatch(c, self.robot, self.scene)
        self.plate_pushes = PlatePushWatch(c, self.collision_watch.link_names, self.scene.plates)
        self._reviewed_at = -1.0
        self._plate_within_range = True
        self._turning_loaded = False
        for _ in range(int(0.5 / time_step)):  # let plates settle in their nests
            self.step()

    def close(self) -> None:
        if p.isConnected(self.client_id):
            p.disconnect(self.client_id)

    # ----------------------------------------------------------------- stepping
    def step(self) -> None:
        """Advance by one physics step (``time_step``, or a multiple of it in free motion)."""
        dt = self._choose_step()
        motions = self.motions
        base_driven = False
        for motion in motions:
            motion.advance(dt)
            base_driven = base_driven or ("base" in motion.resources and not motion.done)
        if not base_driven:
            self.base.command(0.0, 0.0)  # no drive running: the base brakes and stands
        self.base.driven = base_driven
        self._clamp_while_driving(base_driven)
        self.base.update(dt)
        started = time.thread_time()
        p.stepSimulation(physicsClientId=self.client_id)
        self._stop_on_collision()
        self._check_holds(dt)
        self.step_ledger.record(dt, self._iterations, time.thread_time() - started)
        self.base.integrate_odometry(dt)
        self.sim_time += dt
        self.last_step_s = dt
        self.clock.tick(self)
        if any(m.done for m in motions):
            self.motions = [m for m in motions if not m.done]

    def _stop_on_collision(self) -> None:
        """An unintended contact (collision_watch) stops the base at once and fails every running
        motion, naming it; a plate pushed without being held is logged (plate_pushes)."""
        for collision in self.collision_watch.check(self.sim_time):
            self.base.protective_stop()
            for motion in self.motions:
                motion.finish(False, COLLISION, collision.text())
        in_hand = {g.attached_id or g.slipped_id for g in self.grippers.values()}
        self.plate_pushes.check(self.collision_watch.points, in_hand, self.sim_time)

    def _clamp_while_driving(self, base_driven: bool) -> None:
        """The hotel clamp closes when a base motion starts and opens once the base stands."""
        if base_driven and not self._clamped_for_drive:
            self.hotel_clamp.close(held=self._held_plates())
            self._clamped_for_drive = True
        elif not base_driven and self._clamped_for_drive and self.base.stopped():
            self.hotel_clamp.open()
            self._clamped_for_drive = False

    def _check_holds(self, dt: float) -> None:
        """Constraints hold a plate only while friction could (gripper_controller, hotel_clamp)."""
        for gripper in self.grippers.values():
            gripper.check_grip(dt)
        if self.hotel_clamp.constraints:
            self.hotel_clamp.release_pushed(HOLDER_FRICTION)

    def _held_plates(self) -> set[str]:
        return {g.attached_id for g in self.grippers.values() if g.attached_id}

    def _choose_step(self) -> float:
        """Solver iterations and step length for the coming step (see the constants above)."""
        # a plate the attach let go of is held by friction contacts alone: those need the grasp settings
        grasping = any(isinstance(m, GripperMotion) for m in self.motions) or any(
            g.slipped_id and g.loose() for g in self.grippers.values()
        )
        if not grasping and self.sim_time - self._reviewed_at >= STEP_REVIEW_PERIOD - 1e-9:
            self._reviewed_at = self.sim_time
            self._plate_within_range = self.plate_proximity.plate_within_range(self._held_plates())
            turn_rate = max(abs(self.base.w), abs(self.base.w_cmd))
            self._turning_loaded = turn_rate > LOADED_TURN_RATE and bool(
                self.hotel_clamp.resting_on_tray(self._held_plates() | set(self.hotel_clamp.constraints))
            )
        iterations = SOLVER_ITERATIONS_GRASPING if grasping else SOLVER_ITERATIONS
        if iterations != self._iterations:
            self._iterations = iterations
            p.setPhysicsEngineParameter(numSolverIterations=iterations, physicsClientId=self.client_id)
        short = grasping or self._plate_within_range or self._turning_loaded
        if short:
            step, erp = self.time_step, CONSTRAINT_ERP
        elif self.motions and all(motion.resources <= {"base"} for motion in self.motions):
            step, erp = self.time_step * DRIVE_STEP_RATIO, DRIVE_CONSTRAINT_ERP
        else:
            step, erp = self.time_step * FREE_MOTION_STEP_RATIO, FREE_MOTION_CONSTRAINT_ERP
        if step != self._step:
            self._step = step
            p.setPhysicsEngineParameter(fixedTimeStep=step, erp=erp, physicsClientId=self.client_id)
            self.robot.forces.restate()  # force limits are impulses per step in PyBullet (step_forces)
        return step

    def busy(self) -> bool:
        return any(not m.done for m in self.motions)

    def run(self, motion: Motion, timeout_s: float = 120.0) -> Motion:
        """Step until ``motion`` is done (helper for scripts and tests)."""
        end = self.sim_time + timeout_s
        while not motion.done and self.sim_time < end:
            self.step()
        if not motion.done:
            motion.cancel()
            for _ in range(int(2.0 / self.time_step)):
                self.step()
                if motion.done:
                    break
        return motion

    def _start(self, motion: Motion) -> Motion:
        if motion.done:
            return motion
        taken = set().union(*(m.resources for m in self.motions)) if self.motions else set()
        if motion.resources & taken:
            return FailedMotion(motion.name, BUSY, f"busy: {sorted(motion.resources & taken)}")
        self.motions.append(motion)
        return motion

    # ----------------------------------------------------------------- sensors
    def odometry(self) -> tuple[float, float, float]:
        x, y, yaw = self.base.odom
        return float(x), float(y), float(yaw)

    def pose_estimate(self) -> tuple[float, float, float]:
        """The base's pose in the map as the robot believes it (odometry + localisation's correction)."""
        x, y, yaw = self.base.estimate()
        return float(x), float(y), float(yaw)

    def joint_positions(self) -> dict[str, float]:
        return self.robot.joint_positions()

    def is_docked(self) -> bool:
        points = p.getClosestPoints(
            self.robot.id, self.scene.dock, DOCK_SENSOR_RANGE, linkIndexA=-1, physicsClientId=self.client_id
        )
        return bool(points)

    def render_head_camera(self, supersample: int = 1) -> tuple[np.ndarray, np.ndarray, CameraIntrinsics]:
        intrinsics = CameraIntrinsics()
        T_world_optical = self.true_camera_pose()
        rgb, depth = render_rgbd(self.client_id, T_world_optical, intrinsics, supersample=supersample)
        return rgb, depth, intrinsics

    def true_camera_pose(self) -> np.ndarray:
        """T_world_optical of the head camera as mounted (ground truth: rendering and checks only)."""
        return self.robot.link_pose("head_front_camera_rgb_optical_frame") @ self.T_camera_mount_error

    def nest_readings(self) -> list[NestReading]:
        """Every nest, as its presence sensor sees it (a plate there, and which one)."""
        return self.plate_sensing.nest_readings()

    def hotel_readings(self) -> list[HotelSlotReading]:
        """Every hotel pocket, as its presence sensor sees it (the plate's id and type, or "")."""
        return self.plate_sensing.hotel_readings()

    def plate_bottom_pose(self, labware_id: str) -> np.ndarray:
        """T_world_bottom of a plate (its bottom face centre): physics ground truth."""
        return self.plate_sensing.plate_bottom(labware_id)

    def gripper_holds(self, arm: str) -> bool:
        """That gripper holds something, as its fingers' joint states say (closed on it): the
        presence reading a real TIAGo++ has, which needs no label and no contact query."""
        return self.grippers[arm].holds_by_gap()

    def held_labware(self, arm: str) -> str:
        """Plate between that gripper's pads (both touching), or the one attached after a verified grasp,
        as the gripper's identity reader read it ("" if its read failed)."""
        gripper = self.grippers[arm]
        return self.plate_sensing.held_reading(arm, gripper.touching() or gripper.attached_id)

    # ----------------------------------------------------------------- motions
    def drive_to(
        self, x: float, y: float, yaw: float, speed: float | None = None, relative: bool = False
    ) -> Motion:
        """To a map pose; ``relative``: measured from where the base stands (DriveMotion)."""
        if self.is_docked():
            return FailedMotion("drive", "DOCKED", "undock first")
        return self._start(DriveMotion(self.base, x, y, yaw, speed=speed, relative=relative))

    def follow_path(
        self,
        plan: Plan,
        yaw: float,
        speed: float | None = None,
        watch: UnmappedObstacles | None = None,
    ) -> Motion:
        """Drive a planned path (navigation.planner) segment by segment, ending facing ``yaw``;
        with ``watch``, stop short of obstacles the laser sees and the map lacks (guarded_path)."""
        if self.is_docked():
            return FailedMotion("drive", "DOCKED", "undock first")
        motion = path_motion(self.base, plan, yaw, speed=speed)
        return self._start(motion if watch is None else GuardedPathMotion(self, motion, plan, watch))

    def command_velocity(self, linear: float, angular: float, duration_s: float) -> Motion:
        """The base at a twist (m/s, rad/s) for ``duration_s``, then braking to a stand."""
        if self.is_docked():
            return FailedMotion("velocity", "DOCKED", "undock first")
        return self._start(VelocityMotion(self.base, linear, angular, duration_s))

    def dock(self) -> Motion:
        if self.is_docked():
            return CompletedMotion("dock", "already docked")
        approach = self.world.pois[self.world.dock_poi]
        return self._start(docking_motion(self.base, approach, self.world.dock_pose, self.is_docked))

    def undock(self) -> Motion:
        """Drive straight ahead off the dock, as far as the dock POI lies in front of the dock."""
        if not self.is_docked():
            return CompletedMotion("undock", "not docked")
        x, y, yaw = self.pose_estimate()  # the frame the drive closes its loop in
        poi, dock = self.world.pois[self.world.dock_poi], self.world.dock_pose
        distance = math.dist((dock.x, dock.y), (poi.x, poi.y))
        goal = (x + distance * math.cos(yaw), y + distance * math.sin(yaw), yaw)
        motion = DriveMotion(self.base, *goal, speed=0.3, name="undock", relative=True)  # no creep
        motion.phase = "driving"
        return self._start(motion)

    def move_joints(self, targets: dict[str, float], speed_scale: float = 1.0) -> Motion:
        """To joint targets in one segment (a one-point trajectory)."""
        return self.execute_trajectory(JointTrajectory((dict(targets),), speed_scale))

    def execute_trajectory(self, trajectory: JointTrajectory) -> Motion:
        """The joint-trajectory controllers of the trajectory's groups follow it together (the
        timing is the controllers', see robot_port.types.JointTrajectory)."""
        names = trajectory.joint_names
        unknown = [n for n in names if n not in self.robot.joint_index]
        if unknown or not names:
            why = f"unknown joints {unknown}" if unknown else "no targets"
            return FailedMotion(trajectory.name, "BAD_GOAL", why)
        motion = JointTrajectoryMotion(
            self.robot,
            list(trajectory.points),
            trajectory.speed_scale,
            name=trajectory.name,
            min_segment_s=trajectory.min_segment_s,
            resources=frozenset(self._joint_resource(n) for n in names),
        )
        return self._start(motion)

    def follow_timed_trajectory(
        self, names: list[str], times_s: list[float], positions: list, velocities: list | None, name: str
    ) -> Motion:
        """A joint trajectory controller's goal: points with their times (checked by the caller)."""
        if any(n not in self.robot.joint_index for n in names) or not names:
            return FailedMotion(name, "BAD_GOAL", f"unknown joints among {names}")
        groups = frozenset(self._joint_resource(n) for n in names)
        return self._start(
            TimedTrajectoryMotion(self.robot, names, times_s, positions, velocities, name, groups)
        )

    @staticmethod
    def _joint_resource(name: str) -> str:
        try:
            return joint_group(name)
        except ValueError:
            return name.split("_")[0]  # wheels, casters

    def gripper(self, arm: str, close: bool) -> Motion:
        if arm not in rm.ARM_SIDES:
            return FailedMotion("gripper", "BAD_GOAL", f"unknown arm {arm!r}")
        return self._start(GripperMotion(self.grippers[arm], close))

    # ----------------------------------------------------------------- ground truth
    def check_placement(self, labware_id: str, nest: Nest | None = None) -> PlacementCheck:
        """Where a plate really is, and whether it rests in `nest` within tolerance (success
        checks only, never robot control). Raises KeyError for a nest the world does not have."""
        return self.plate_sensing.check_placement(labware_id, nest)
