"""Bounded waits for the sequencer's coroutines: a pause, a future within a time, the workcell.

Why: the sequencer's execute callbacks are coroutines on one SingleThreadedExecutor, so a wait
must yield to the executor, never block it, and every wait must end (a sub-goal or a service
that never answers must not hold a task forever). Each function takes the node whose timers it
uses. Lives on the sequencer's executor thread.
"""

from __future__ import annotations

import logging
import time
import uuid
from typing import Any

from labware_interfaces.msg import ErrorCodes
from labware_interfaces.srv import DescribeWorkcell
from rclpy.action.client import ClientGoalHandle
from rclpy.node import Node
from rclpy.task import Future
from unique_identifier_msgs.msg import UUID

from labware_model.workcell import WorkcellDescription
from tiago_sim.sequencer.task_run import StepFailed

log = logging.getLogger("tiago_sim.sequencer")


async def sleep(node: Node, seconds: float) -> None:
    """Wait without blocking the executor (a one-shot timer completes a future)."""
    done = Future()

    def fire() -> None:
        timer.cancel()
        done.set_result(True)

    timer = node.create_timer(seconds, fire)
    await done
    node.destroy_timer(timer)


async def within(node: Node, future: Future, seconds: float) -> bool:
    """Wait for `future` at most `seconds` without blocking the executor; True if it is done."""
    if future.done():
        return True
    woken = Future()

    def wake(*_args: Any) -> None:
        if not woken.done():
            woken.set_result(None)

    timer = node.create_timer(max(seconds, 1e-3), wake)
    future.add_done_callback(wake)
    try:
        await woken
    finally:
        timer.cancel()
        node.destroy_timer(timer)
    return future.done()


async def wait_answering(node: Node, client: Any, what: str, timeout_s: float, answered: set[str]) -> None:
    """Wait until a live server of action `what` answers (once per action; StepFailed after
    `timeout_s`). The probe is a cancel request for a goal id nobody sent: the server answers
    "unknown goal" and cancels nothing.

    Why not `server_is_ready` alone: a server killed with SIGKILL stays discovered until its DDS
    lease ends, so after a restart of the robot side a goal could go to the dead server only."""
    if what in answered:
        return
    deadline = time.monotonic() + timeout_s
    while True:
        if client.server_is_ready():
            nobodys_goal = ClientGoalHandle(client, UUID(uuid=list(uuid.uuid4().bytes)), None)
            if await within(node, client._cancel_goal_async(nobodys_goal), 1.0):
                answered.add(what)
                return
        if time.monotonic() > deadline:
            raise StepFailed(ErrorCodes.INTERNAL, f"robot not available: {what} does not answer")
        await sleep(node, 0.1)


async def describe_workcell(node: Node, client: Any, attempts: int, timeout_s: float) -> WorkcellDescription:
    """Ask /describe_workcell up to `attempts` times, `timeout_s` each (an unanswered request is
    withdrawn before the next); raises StepFailed(INTERNAL) when no answer came."""
    attempts, timeout_s = int(attempts), float(timeout_s)
    for attempt in range(1, attempts + 1):
        future = client.call_async(DescribeWorkcell.Request())
        if await within(node, future, timeout_s):
            return WorkcellDescription.from_message(future.result())
        client.remove_pending_request(future)
        log.warning(
            "/describe_workcell: no answer within %g s (attempt %d of %d)", timeout_s, attempt, attempts
        )
    raise StepFailed(
        ErrorCodes.INTERNAL,
        f"robot not available: /describe_workcell answered none of {attempts} requests in {timeout_s:g} s",
    )
