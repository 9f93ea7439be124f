"""The robot's joint trajectory controllers on ROS 2, as gazebo_ros2_control runs them beside Gazebo.

Why: a real TIAGo++ moves its arms, torso, head and grippers through one FollowJointTrajectory
action per controller (`/arm_left_controller/follow_joint_trajectory`, ...; PAL's names,
docs/reference/robot-interfaces.md). The simulator offers the same actions, so that software
written against a robot's interfaces runs against the twin unchanged. Each goal runs on the sim
thread as a `TimedTrajectoryMotion` (the points at their times) or, for a gripper, as a gripper
command that stops on what the fingers meet: closing when the last point closes the fingers past
half their travel, else opening.

As ros2_controllers' JointTrajectoryController does: a goal whose trajectory is not valid for the
controller (joints it does not have, a joint of it missing, points without a position per joint,
times that do not increase) is rejected, with the reason logged; a new goal preempts the running
one (which aborts, saying so); a cancelled goal stops where the joints are; a goal whose joints do
not settle at the last point ends with GOAL_TOLERANCE_VIOLATED.

Threads: the goal callbacks and each goal's execution run on the node's executor threads; the
motions run on the sim thread (jobs).
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Any

from control_msgs.action import FollowJointTrajectory
from rclpy.action import GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from trajectory_msgs.msg import JointTrajectoryPoint

from robot_port.tiago_interfaces import controller_action
from robot_port.types import JOINT_GROUPS
from tiago_description import robot_model as rm
from tiago_sim.sim_node.action_server import cancellable_server
from tiago_sim.sim_node.localisation_topics import stamp_of
from tiago_sim.sim_node.sim_thread import SimThread

log = logging.getLogger(__name__)

FEEDBACK_PERIOD_S = 0.2
"""Wall seconds between a goal's feedback messages (a controller sends one per update; at 20 times
real time that would be thousands a second)."""
MOTION_ANSWER_TIMEOUT_S = 60.0


def trajectory_problem(joints: list[str], trajectory: Any) -> str:
    """Why a trajectory_msgs/JointTrajectory is not a valid goal for a controller of `joints`; ""
    when it is."""
    names = list(trajectory.joint_names)
    if not names or not trajectory.points:
        return "the trajectory has no joints or no points"
    unknown = sorted(set(names) - set(joints))
    if unknown:
        return f"joints {unknown} do not belong to this controller ({', '.join(joints)})"
    missing = [name for name in joints if name not in names]
    if missing or len(set(names)) != len(names):
        return f"partial or repeated joints (partial goals are not allowed): missing {missing}"
    previous = -1.0
    for index, point in enumerate(trajectory.points):
        if len(point.positions) != len(names):
            return f"point {index} has {len(point.positions)} positions for {len(names)} joints"
        if len(point.velocities) not in (0, len(names)):
            return f"point {index} has {len(point.velocities)} velocities for {len(names)} joints"
        at = _seconds(point)
        if at <= previous or at <= 0.0:
            return f"point {index}'s time_from_start {at:.3f} s does not come after the one before"
        previous = at
    return ""


def _seconds(point: JointTrajectoryPoint) -> float:
    return point.time_from_start.sec + point.time_from_start.nanosec * 1e-9


class TrajectoryControllers:
    """One FollowJointTrajectory action server per joint group of the robot (JOINT_GROUPS)."""

    def __init__(self, node: Node, sim_thread: SimThread) -> None:
        self.node = node
        self.sim_thread = sim_thread
        self._lock = threading.Lock()
        self._running: dict[str, tuple[Any, Any]] = {}  # group -> (goal handle, motion)
        self.goals = dict.fromkeys(JOINT_GROUPS, 0)  # goals run, per controller
        group = ReentrantCallbackGroup()
        self.servers = [
            cancellable_server(
                node,
                FollowJointTrajectory,
                controller_action(name),
                lambda handle, name=name: self._execute(name, handle),
                group,
                check=lambda goal, name=name: self._check(name, goal),
            )
            for name in JOINT_GROUPS
        ]

    def _check(self, group: str, goal: Any) -> GoalResponse:
        problem = trajectory_problem(rm.controller_joints(group), goal.trajectory)
        if problem:
            log.warning("%s: goal rejected: %s", controller_action(group), problem)
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def _start(self, group: str, handle: Any, job: Any) -> Any:
        """Stop the group's running goal, if any (it aborts as preempted), wait until its joints
        stand, then start this goal's motion; one at a time, so two new goals cannot both start."""
        with self._lock:
            running = self._running.get(group)
            if running is not None:
                old = running[1]
                self.sim_thread.call(lambda _sim: old.cancel())
                old.finished.wait(MOTION_ANSWER_TIMEOUT_S)
            motion = self.sim_thread.run(job, MOTION_ANSWER_TIMEOUT_S)
            self._running[group] = (handle, motion)
        return motion

    def _execute(self, group: str, handle: Any) -> FollowJointTrajectory.Result:
        self.goals[group] += 1
        trajectory = handle.request.trajectory
        names = list(trajectory.joint_names)
        times = [_seconds(point) for point in trajectory.points]
        positions = [list(point.positions) for point in trajectory.points]
        velocities = [list(point.velocities) for point in trajectory.points]
        timed = velocities if all(velocities) else None
        label = f"{group}_controller"
        if group.startswith("gripper_"):  # the fingers close or open as a gripper command moves them
            closing = sum(positions[-1]) / len(names) < rm.FINGER_TRAVEL / 2
            side = group.removeprefix("gripper_")
            motion = self._start(group, handle, lambda sim: sim.gripper(side, closing))
        else:
            job = lambda sim: sim.follow_timed_trajectory(names, times, positions, timed, label)  # noqa: E731
            motion = self._start(group, handle, job)
        result = FollowJointTrajectory.Result()
        self._feedback(handle, names, motion)  # one at the start: a short goal may end before the next
        while not motion.finished.wait(FEEDBACK_PERIOD_S):
            if handle.is_cancel_requested:
                self.sim_thread.call(lambda _sim: motion.cancel())
            else:
                self._feedback(handle, names, motion)
        with self._lock:
            if self._running.get(group, (None,))[0] is handle:
                del self._running[group]
        if motion.success:
            handle.succeed()
            result.error_code = FollowJointTrajectory.Result.SUCCESSFUL
            return result
        if motion.error_code == "CANCELED":
            result.error_string = "canceled" if handle.is_cancel_requested else "preempted by a new goal"
            if handle.is_cancel_requested:
                handle.canceled()
            else:
                handle.abort()
            return result
        handle.abort()
        result.error_code = (
            FollowJointTrajectory.Result.GOAL_TOLERANCE_VIOLATED
            if motion.error_code == "MOTION_FAILED"
            else FollowJointTrajectory.Result.INVALID_GOAL
        )
        result.error_string = f"{motion.error_code}: {motion.message}"
        return result

    def _feedback(self, handle: Any, names: list[str], motion: Any) -> None:
        """The joints' positions now (actual) and where the trajectory wants them (desired)."""

        def read(sim: Any) -> tuple[float, list[float], list[float]]:
            here = sim.joint_positions()
            sample = getattr(motion, "_sample", None)
            wanted = sample(motion.elapsed_s)[0] if sample is not None else [here[n] for n in names]
            return sim.sim_time, [here[n] for n in names], [float(v) for v in wanted]

        try:
            sim_time, actual, desired = self.sim_thread.run(read, MOTION_ANSWER_TIMEOUT_S)
        except Exception:  # noqa: BLE001 - the simulation is stopping: the goal ends with it
            time.sleep(FEEDBACK_PERIOD_S)
            return
        feedback = FollowJointTrajectory.Feedback()
        feedback.header.stamp = stamp_of(sim_time)
        feedback.joint_names = names
        feedback.actual.positions = actual
        feedback.desired.positions = desired
        feedback.error.positions = [w - a for w, a in zip(desired, actual, strict=True)]
        handle.publish_feedback(feedback)
