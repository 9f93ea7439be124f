"""One step of a task: its sub-goal sent to the robot's action, its result awaited within bounds.

Why apart from the node: sending a sub-goal, following its feedback and bounding every wait is
the same for every step of every task, and the node keeps the task-level decisions. Runs on the
sequencer's executor thread (coroutines that await rclpy futures).
"""

from __future__ import annotations

import logging
from typing import Any

from action_msgs.msg import GoalStatus
from labware_interfaces.action import Gripper, MarkerMotion, NavigateToPoi, PlayMotion, Undock
from labware_interfaces.msg import ErrorCodes
from rclpy.node import Node

from tiago_sim.sequencer.plans import Step
from tiago_sim.sequencer.task_run import StepFailed, TaskRun
from tiago_sim.sequencer.waits import wait_answering, within

log = logging.getLogger("tiago_sim.sequencer")

SUB_ACTIONS = {
    "undock": (Undock, "/undock"),
    "navigate": (NavigateToPoi, "/navigate_to_poi"),
    "play_motion": (PlayMotion, "/play_motion"),
    "gripper": (Gripper, "/gripper"),
    "marker_motion": (MarkerMotion, "/marker_motion"),
}
# The task's code when a sub-goal gives no result within step_timeout_s (else MOTION_FAILED).
TIMEOUT_CODES = {"navigate": ErrorCodes.NAVIGATION_FAILED, "undock": ErrorCodes.NAVIGATION_FAILED}


def _param(node: Node, name: str) -> float:
    return float(node.get_parameter(name).value)


async def run_step(node: Node, client: Any, run: TaskRun, step: Step, which: str, answering: set[str]) -> Any:
    """Send `step`'s sub-goal over `client`, follow its feedback into `run`, return its result;
    StepFailed for a refusal, a failure, a cancel or a wait past its bound."""
    kind, topic = SUB_ACTIONS[step.action]
    server_wait_s = _param(node, "server_wait_s")
    await wait_answering(node, client, topic, server_wait_s, answering)
    goal = kind.Goal()
    for field_name, value in step.goal.items():
        setattr(goal, field_name, value)

    on_feedback, silence = run.follow_sub_goal(step.phase)
    log.info("%s: %s", which, step.describe())
    sent = client.send_goal_async(goal, feedback_callback=on_feedback)
    if not await within(node, sent, server_wait_s):
        # an answer that comes after all must not leave a goal running that nobody waits for
        sent.add_done_callback(lambda done: done.result().accepted and done.result().cancel_goal_async())
        raise StepFailed(ErrorCodes.INTERNAL, f"{which} ({step.describe()}): the goal was not answered")
    sub_goal = sent.result()
    if not sub_goal.accepted:
        raise StepFailed(ErrorCodes.INTERNAL, f"{step.describe()}: goal rejected")
    run.sub_goal = sub_goal
    if run.goal_handle.is_cancel_requested:
        sub_goal.cancel_goal_async()
    try:
        response = await result_within_step_timeout(node, sub_goal, step, which)
    finally:
        run.sub_goal = None
        silence()
    sub_result = response.result
    if response.status == GoalStatus.STATUS_CANCELED or sub_result.error_code == ErrorCodes.CANCELED:
        raise StepFailed(ErrorCodes.CANCELED, f"canceled during {step.describe()}: {sub_result.message}")
    if not sub_result.success:
        raise StepFailed(
            sub_result.error_code or ErrorCodes.INTERNAL, f"{step.describe()}: {sub_result.message}"
        )
    if step.expect_holding and not sub_result.holding:
        raise StepFailed(ErrorCodes.GRASP_FAILED, f"{step.describe()}: nothing between the fingers")
    run.step_progress, run.step_remaining_s = 1.0, 0.0
    return sub_result


async def result_within_step_timeout(node: Node, sub_goal: Any, step: Step, which: str) -> Any:
    """The sub-goal's result; past `step_timeout_s` the sub-goal is cancelled and the step fails."""
    timeout_s = _param(node, "step_timeout_s")
    result = sub_goal.get_result_async()
    if await within(node, result, timeout_s):
        return result.result()
    log.warning("%s (%s): no result within %g s, cancelling it", which, step.describe(), timeout_s)
    sub_goal.cancel_goal_async()
    cancel_wait_s = _param(node, "cancel_wait_s")
    ended = await within(node, result, cancel_wait_s)
    code = TIMEOUT_CODES.get(step.action, ErrorCodes.MOTION_FAILED) if ended else ErrorCodes.INTERNAL
    after = "cancelled" if ended else f"cancelled, and it did not end within {cancel_wait_s:g} s either"
    raise StepFailed(
        code, f"{which} ({step.phase}: {step.describe()}) timed out after {timeout_s:g} s: {after}"
    )
