"""`/play_motion2` as a TIAGo++ offers it: named motions played through the robot's controllers.

Why: PAL's play_motion2 node runs beside a TIAGo++'s controllers and plays a motion by name
(play_motion2_msgs/action/PlayMotion2), listing its motions and whether one is ready on two
services. The simulator plays the robot's motion library (tiago_sim.sim_node.named_motions) the
same way: as play_motion2 does, it is a client of the controllers' FollowJointTrajectory actions
(one goal per controller, sent together), so a motion shares the controllers' rules (a goal
preempts a running one; a cancel stops the joints where they are). Not modelled: play_motion2's
MoveIt-planned approach (`skip_planning` false): the approach here is always the joint-space
interpolation play_motion2 uses with planning skipped or disabled.

Threads: each goal runs on one of the node's executor threads and waits for its controller goals'
answers, which arrive on others.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Mapping
from typing import Any

from action_msgs.msg import GoalStatus
from builtin_interfaces.msg import Duration
from control_msgs.action import FollowJointTrajectory
from play_motion2_msgs.action import PlayMotion2
from play_motion2_msgs.srv import IsMotionReady, ListMotions
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from trajectory_msgs.msg import JointTrajectoryPoint

from robot_port.action_client import ThreadSafeActionClient
from robot_port.tiago_interfaces import IS_MOTION_READY, LIST_MOTIONS, PLAY_MOTION2, controller_action
from robot_port.types import JOINT_GROUPS
from tiago_description import robot_model as rm
from tiago_description.robot_limits import active_limits
from tiago_sim.sim_node.action_server import cancellable_server
from tiago_sim.sim_node.named_motions import NamedMotion, TimedRows
from tiago_sim.sim_node.sim_thread import SimThread

log = logging.getLogger(__name__)

ANSWER_TIMEOUT_S = 60.0
"""Wall seconds a controller may take to accept a goal, and the simulation to read the joints."""


def controller_goals(timed: TimedRows, current: Mapping[str, float]) -> dict[str, FollowJointTrajectory.Goal]:
    """One goal per controller that moves a joint of the motion; a controller's other joints hold
    where they stand (a controller takes whole goals only)."""
    goals = {}
    for group in JOINT_GROUPS:
        joints = rm.controller_joints(group)
        if not set(joints) & set(timed.joints):
            continue
        goal = FollowJointTrajectory.Goal()
        goal.trajectory.joint_names = joints
        for row, at in zip(timed.rows, timed.times_s, strict=True):
            values = dict(zip(timed.joints, row, strict=True))
            seconds = int(at)
            point = JointTrajectoryPoint(
                positions=[float(values.get(joint, current[joint])) for joint in joints],
                time_from_start=Duration(sec=seconds, nanosec=int((at - seconds) * 1e9)),
            )
            goal.trajectory.points.append(point)
        goals[group] = goal
    return goals


class PlayMotion2Server:
    """The `/play_motion2` action and its two services, over the controllers' actions."""

    def __init__(self, node: Node, sim_thread: SimThread, motions: Mapping[str, NamedMotion]) -> None:
        self.sim_thread = sim_thread
        self.motions = dict(motions)
        self.played = 0
        group = ReentrantCallbackGroup()
        self.controllers = {
            name: ThreadSafeActionClient(
                node, FollowJointTrajectory, controller_action(name), callback_group=group
            )
            for name in JOINT_GROUPS
        }
        self.server = cancellable_server(node, PlayMotion2, PLAY_MOTION2, self._execute, group)
        node.create_service(ListMotions, LIST_MOTIONS, self._list, callback_group=group)
        node.create_service(IsMotionReady, IS_MOTION_READY, self._is_ready, callback_group=group)

    def _list(self, _request: Any, response: ListMotions.Response) -> ListMotions.Response:
        response.motion_keys = sorted(self.motions)
        return response

    def _is_ready(self, request: Any, response: IsMotionReady.Response) -> IsMotionReady.Response:
        response.is_ready = request.motion_key in self.motions
        return response

    def _execute(self, handle: Any) -> PlayMotion2.Result:
        result = PlayMotion2.Result()
        motion = self.motions.get(handle.request.motion_name)
        if motion is None:
            handle.abort()
            result.error = (
                f"unknown motion {handle.request.motion_name!r}: known are {', '.join(sorted(self.motions))}"
            )
            return result
        self.played += 1
        current = self.sim_thread.run(lambda sim: sim.joint_positions(), ANSWER_TIMEOUT_S)
        timed = motion.timed_from(current, active_limits().joint_velocity)
        error = self._run(handle, controller_goals(timed, current))
        if not error:
            handle.succeed()
            result.success = True
        elif handle.is_cancel_requested:
            handle.canceled()
            result.error = error
        else:
            handle.abort()
            result.error = error
        return result

    def _run(self, handle: Any, goals: dict[str, FollowJointTrajectory.Goal]) -> str:
        """Send the controller goals together and wait for all; "" if every one succeeded, else why not."""
        answered = threading.Event()
        pending: dict[str, Any] = {}
        lock = threading.Lock()

        def on_result(group: str, future: Any) -> None:
            with lock:
                pending[group] = future.result()
                if len(pending) == len(goals):
                    answered.set()

        handles = {}
        for group, goal in goals.items():
            sent = self.controllers[group].send_goal_async(goal)
            accepted = threading.Event()
            sent.add_done_callback(lambda _future, accepted=accepted: accepted.set())
            if not accepted.wait(ANSWER_TIMEOUT_S) or not sent.result().accepted:
                for other in handles.values():
                    other.cancel_goal_async()
                return f"{controller_action(group)} did not accept its part"
            handles[group] = sent.result()
            handles[group].get_result_async().add_done_callback(lambda future, g=group: on_result(g, future))
        cancelled = False
        while not answered.wait(0.05):
            if handle.is_cancel_requested and not cancelled:
                for goal_handle in handles.values():
                    goal_handle.cancel_goal_async()
                cancelled = True
        failed = [
            f"{controller_action(group)}: {answer.result.error_string or 'status ' + str(answer.status)}"
            for group, answer in sorted(pending.items())
            if answer.status != GoalStatus.STATUS_SUCCEEDED
        ]
        return "; ".join(failed)
