"""The simulated TIAGo++ behind the hardware port (robot_port.RobotHardware), in the same process.

Why in-process: campaigns and CI run thousands of goals, and a reading through this adapter costs
one job on the sim thread, as it did before the port existed. Every reading and every command is
such a job (PyBullet lives on the sim thread alone); a command's Motion is handed back wrapped as
the port's Execution, whose cancel is a job too. Navigation goals go to the navigation stand-in
(navigation.Navigation), which runs them beside the skills as a navigation stack would.

Idealisations the port does not hide (docs/explanation/hardware-port.md): a camera frame is
rendered at the instant it is asked for, with the joint readings of that instant, and comes back
without transport delay; readings come back without latency beyond the job's wait.
"""

from __future__ import annotations

import concurrent.futures
from collections.abc import Callable
from typing import Any, TypeVar

from robot_port.execution import Execution
from robot_port.hardware import HardwareUnavailable
from robot_port.types import CameraFrame, JointTrajectory, LaserScan, Pose2D
from tiago_description import transforms as tf
from tiago_sim.sim_node.navigation import Navigation
from tiago_sim.sim_node.sim_thread import SimThread

T = TypeVar("T")

ANSWER_TIMEOUT_S = 60.0
"""Wall seconds a reading may take before the simulator counts as gone (a frame under heavy load
takes about a second)."""
_RESULT_FIELDS = ("holding", "opening_m")


class MotionExecution:
    """A Motion of the Simulation, seen from other threads as the port's Execution."""

    def __init__(self, motion: Any, sim_thread: SimThread) -> None:
        self.motion = motion
        self.name = motion.name
        self._sim_thread = sim_thread

    def _lost(self) -> bool:
        return not self.motion.done and self._sim_thread.stopped

    @property
    def done(self) -> bool:
        return bool(self.motion.done) or self._sim_thread.stopped

    @property
    def success(self) -> bool:
        return bool(self.motion.done and self.motion.success)

    @property
    def error_code(self) -> str:
        return "INTERNAL" if self._lost() else str(self.motion.error_code)

    @property
    def message(self) -> str:
        return "simulation stopped" if self._lost() else str(self.motion.message)

    @property
    def progress(self) -> float:
        return float(self.motion.progress)

    @property
    def phase(self) -> str:
        return str(self.motion.phase)

    @property
    def remaining_s(self) -> float:
        return float(self.motion.remaining_s)

    @property
    def result(self) -> dict[str, Any]:
        return {name: getattr(self.motion, name) for name in _RESULT_FIELDS if hasattr(self.motion, name)}

    def wait(self, timeout_s: float) -> bool:
        self.motion.finished.wait(timeout_s)
        return self.done

    def cancel(self) -> None:
        self._sim_thread.call(lambda _sim: self.motion.cancel())


class SimulatedHardware:
    """robot_port.RobotHardware on the Simulation owned by `sim_thread`."""

    def __init__(self, sim_thread: SimThread, navigation: Navigation) -> None:
        self.sim_thread = sim_thread
        self.navigation = navigation

    def _ask(self, job: Callable[[Any], T]) -> T:
        try:
            return self.sim_thread.run(job, ANSWER_TIMEOUT_S)
        except concurrent.futures.TimeoutError:
            raise HardwareUnavailable("the simulation did not answer in time") from None
        except RuntimeError:
            if self.sim_thread.stopped:
                raise HardwareUnavailable("the simulation stopped") from None
            raise

    def _start(self, command: Callable[[Any], Any]) -> Execution:
        return MotionExecution(self._ask(command), self.sim_thread)

    # -- clock and readings ------------------------------------------------------------------
    def now(self) -> float:
        return float(self.sim_thread.sim_time)

    def joint_positions(self) -> dict[str, float]:
        return self._ask(lambda sim: dict(sim.joint_positions()))

    def odometry(self) -> Pose2D:
        return self._ask(lambda sim: sim.odometry())

    def pose_estimate(self) -> Pose2D:
        return self._ask(lambda sim: sim.pose_estimate())

    def is_docked(self) -> bool:
        return self._ask(lambda sim: sim.is_docked())

    def laser_scan(self) -> LaserScan:
        def scan(sim: Any) -> LaserScan:
            reading = sim.laser.read(sim.sim_time, sim.odometry())
            spec = reading.spec
            return LaserScan(
                ranges=reading.ranges,
                angle_min=spec.angle_min,
                angle_increment=spec.angle_increment,
                range_min=spec.range_min,
                range_max=spec.range_max,
                mount=(spec.mount_x, spec.mount_y, spec.mount_yaw),
                odometry=tuple(reading.odometry),
                stamp_s=reading.sim_time,
            )

        return self._ask(scan)

    def capture_head_camera(self) -> CameraFrame:
        def capture(sim: Any) -> CameraFrame:
            rgb, depth, intrinsics = sim.render_head_camera()
            joints, odometry = dict(sim.joint_positions()), tuple(sim.odometry())
            return CameraFrame(rgb, depth, intrinsics, joints, odometry, sim.sim_time)

        return self._ask(capture)

    # -- commands ------------------------------------------------------------------------------
    def follow_joint_trajectory(self, trajectory: JointTrajectory) -> Execution:
        return self._start(lambda sim: sim.execute_trajectory(trajectory))

    def gripper(self, side: str, close: bool) -> Execution:
        return self._start(lambda sim: sim.gripper(side, close))

    def command_velocity(self, linear_mps: float, angular_radps: float, duration_s: float) -> Execution:
        return self._start(lambda sim: sim.command_velocity(linear_mps, angular_radps, duration_s))

    def drive_to(self, goal: Pose2D, speed_mps: float) -> Execution:
        def drive(sim: Any) -> Any:
            # the odometry goal in the map frame the drive closes its loop in, at the instant it
            # starts; the drive is relative, so localisation holds the map frame still under it
            odom_to_map = tf.compose_planar(sim.pose_estimate(), tf.invert_planar(sim.odometry()))
            return sim.drive_to(*tf.compose_planar(odom_to_map, goal), speed=speed_mps, relative=True)

        return self._start(drive)

    def navigate_to(self, goal: Pose2D, goal_name: str) -> Execution:
        return self.navigation.navigate(goal, goal_name)

    def plan_path(self, start: Pose2D, goal: Pose2D) -> tuple[Pose2D, ...]:
        return self.navigation.plan_path(start, goal)

    def dock(self) -> Execution:
        return self._start(lambda sim: sim.dock())

    def undock(self) -> Execution:
        return self._start(lambda sim: sim.undock())
