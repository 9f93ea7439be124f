"""RobotHardware: the one port through which the robot's skills read and move a TIAGo++.

What it holds is what a TIAGo++ offers its software, and no more: encoders, odometry, the base
laser, the head camera, joint-trajectory controllers per group, the grippers, the base velocity
command, and the navigation stack's goals (navigate to a pose, a short straight approach, dock,
undock) and plans (a path, without driving it). The navigation stack (Nav2 and PAL's docking on a
TIAGo++) is on the hardware's side of the port: its planner, localisation and docking are the
vendor's, not our skills.

Commands return an ``Execution`` at once; readings answer at once. Implementations: the simulator
(``tiago_sim.sim_node.hardware.SimulatedHardware``, in the same process) and, for a real robot,
an adapter on its ROS 2 interfaces. Any thread may call any method.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from robot_port.execution import Execution
from robot_port.types import CameraFrame, JointTrajectory, LaserScan, Pose2D


class HardwareUnavailable(RuntimeError):
    """The hardware did not answer (a simulator that stopped, a driver that went away)."""


@runtime_checkable
class RobotHardware(Protocol):
    """The robot as its skills see it (see the module docstring)."""

    # -- clock ----------------------------------------------------------------------------
    def now(self) -> float:
        """The robot's clock in seconds (ROS time: simulated time in the simulator)."""

    # -- readings -------------------------------------------------------------------------
    def joint_positions(self) -> dict[str, float]:
        """Every joint's encoder reading (rad, or m for the torso and the fingers)."""

    def odometry(self) -> Pose2D:
        """The base's pose in the odometry frame (wheel odometry, drifting)."""

    def pose_estimate(self) -> Pose2D:
        """The base's pose in the map frame as localisation believes it."""

    def is_docked(self) -> bool:
        """The charging contacts touch the dock."""

    def laser_scan(self) -> LaserScan:
        """A base-laser scan taken now."""

    def capture_head_camera(self) -> CameraFrame:
        """A head-camera frame taken now, with the joint and odometry readings of its instant.
        Callers take it once the head stands (after the head's trajectory has ended)."""

    # -- the arm, torso, head and grippers -------------------------------------------------
    def follow_joint_trajectory(self, trajectory: JointTrajectory) -> Execution:
        """Run a trajectory on its groups' controllers; fails at once (``BUSY``) when a group is
        moving for another command, (``BAD_GOAL``) for joints the robot does not have."""

    def gripper(self, side: str, close: bool) -> Execution:
        """Open or close a gripper; its ``result`` says whether the fingers stopped on something
        (``holding``) and their final ``opening_m``."""

    # -- the base ----------------------------------------------------------------------------
    def command_velocity(self, linear_mps: float, angular_radps: float, duration_s: float) -> Execution:
        """Drive the base at a twist for ``duration_s`` (the base stops at the end, or on a cancel)."""

    def drive_to(self, goal: Pose2D, speed_mps: float) -> Execution:
        """A short straight drive (no planning) to a pose in the odometry frame: it stays fixed to
        the floor whatever localisation corrects meanwhile (a marker-guided final approach)."""

    def navigate_to(self, goal: Pose2D, goal_name: str) -> Execution:
        """The navigation stack's goal: plan on the map, drive around what the laser sees."""

    def plan_path(self, start: Pose2D, goal: Pose2D) -> tuple[Pose2D, ...]:
        """The navigation stack's global plan from ``start`` to ``goal`` (map frame), made without
        driving it: poses along the path, each with the heading the base drives on from there, the
        goal last; empty when the planner finds none. Blocks while the planner plans (a second at
        most on a TIAGo++; milliseconds in the simulator)."""

    def dock(self) -> Execution:
        """Onto the charging dock from its approach pose (the vendor's docking)."""

    def undock(self) -> Execution:
        """Straight off the dock to its approach pose."""
