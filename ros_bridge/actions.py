"""Call a ROS 2 action from any thread: send goal, watch feedback, wait for the result, cancel.

`ActionCaller.send` returns an `ActionGoal` (ros_bridge.goal_status: the status contract every
caller uses) and keeps, for each goal, a `_GoalOverRos` that is the goal's creator: it turns
rclpy's answers (goal accepted, feedback, result) into the status's set_* calls and sends cancel
requests.

Threads: `ActionCaller` and `ActionGoal` are used from caller threads (SiLA handlers). Every
rclpy call is handed to the ROS thread of a `RosRuntime`; rclpy's answers arrive there, so the
goal's progress listeners and completion callbacks run on the ROS thread: keep them short.

When the runtime ends (stopped, or its ROS thread died), every goal still open ends at once with
GoalAbandoned naming why: nothing could answer it any more.

Our actions share one feedback shape (progress 0..1, phase, remaining_time_s) and one result
shape (success, error_code, message); other fields of the result stay reachable as `result`.
"""

from __future__ import annotations

import concurrent.futures
import logging
import threading
import time
import uuid
from collections.abc import Callable
from typing import Any

from action_msgs.msg import GoalStatus
from rclpy.action import ActionClient
from rclpy.action.client import ClientGoalHandle
from unique_identifier_msgs.msg import UUID

from ros_bridge.errors import BridgeError, BridgeTimeout, ServerUnavailable
from ros_bridge.goal_status import ActionGoal, ActionOutcome
from ros_bridge.progress import GoalProgress
from ros_bridge.runtime import RosRuntime

logger = logging.getLogger(__name__)

_STATUS_NAMES = {
    GoalStatus.STATUS_SUCCEEDED: "SUCCEEDED",
    GoalStatus.STATUS_ABORTED: "ABORTED",
    GoalStatus.STATUS_CANCELED: "CANCELED",
    GoalStatus.STATUS_UNKNOWN: "UNKNOWN",
}


class _GoalOverRos:
    """The creator of one `ActionGoal`: finishes it from rclpy's answers, cancels it on request.

    Threads: the `_on_*` methods run on the ROS thread (rclpy callbacks) and never raise: rclpy
    re-raises a callback's exception from the executor, which would end the ROS thread; one that
    fails ends the goal with BridgeError instead. `cancel` runs on the caller's thread and hands
    the rclpy call over."""

    def __init__(self, runtime: RosRuntime, action_name: str) -> None:
        self._runtime = runtime
        self.status = ActionGoal(action_name, cancel_request=self.cancel)
        self._lock = threading.Lock()  # the handle and the cancel wish, between caller and ROS thread
        self._ros_handle: ClientGoalHandle | None = None
        self._cancel_requested = False

    @property
    def _name(self) -> str:
        return self.status.action_name

    def cancel(self, timeout_s: float) -> bool:
        """Ask the server to cancel; True if it agreed (or the goal had not been accepted yet)."""
        with self._lock:
            self._cancel_requested = True
            ros_handle = self._ros_handle
        if ros_handle is None:
            return True  # cancelled as soon as the acceptance arrives (see _on_goal_response)
        answer: concurrent.futures.Future[Any] = concurrent.futures.Future()

        def cancel_on_ros_thread() -> None:
            ros_future = ros_handle.cancel_goal_async()
            ros_future.add_done_callback(lambda done: _copy_ros_future(done, answer))

        self._runtime.call(cancel_on_ros_thread, timeout_s)
        try:
            response = answer.result(timeout=timeout_s)
        except concurrent.futures.TimeoutError as error:
            raise BridgeTimeout(
                f"{self._name}: no answer to the cancel request within {timeout_s:.1f} s"
            ) from error
        return bool(response.goals_canceling)

    # --- ROS thread only below ---

    def on_feedback(self, feedback_message: Any) -> None:
        self._guarded("feedback", self._on_feedback, feedback_message)

    def on_goal_response(self, response_future: Any) -> None:
        self._guarded("the goal response", self._on_goal_response, response_future)

    def on_result(self, result_future: Any) -> None:
        self._guarded("the result", self._on_result, result_future)

    def _guarded(self, what: str, handle: Callable[[Any], None], answer: Any) -> None:
        try:
            handle(answer)
        except Exception as error:  # noqa: BLE001 - must not reach the executor (see the class)
            logger.exception("%s: handling %s failed", self._name, what)
            self.status.set_exception(BridgeError(f"{self._name}: handling {what} failed: {error}"))

    def _on_feedback(self, feedback_message: Any) -> None:
        feedback = feedback_message.feedback
        self.status.update_progress(
            float(getattr(feedback, "progress", 0.0)),
            str(getattr(feedback, "phase", "")),
            float(getattr(feedback, "remaining_time_s", 0.0)),
        )

    def _on_goal_response(self, response_future: Any) -> None:
        error = response_future.exception()
        if error is not None:
            self.status.set_exception(BridgeError(f"{self._name}: goal request failed: {error}"))
            return
        ros_handle: ClientGoalHandle = response_future.result()
        if not ros_handle.accepted:
            self.status.set_rejected(f"{self._name}: goal rejected by the server")
            return
        with self._lock:
            self._ros_handle = ros_handle
            cancel_now = self._cancel_requested
        if cancel_now:
            if self.status.done:
                logger.warning("%s: accepted after it was withdrawn: cancelling it", self._name)
            ros_handle.cancel_goal_async().add_done_callback(
                lambda answer: self._guarded("the cancel answer", self._on_late_cancel_answer, answer)
            )
        self.status.set_accepted()
        ros_handle.get_result_async().add_done_callback(self.on_result)

    def _on_late_cancel_answer(self, cancel_future: Any) -> None:
        """The answer to a cancel sent when the acceptance came: only logged (nobody waits for it)."""
        error = cancel_future.exception()
        if error is not None:
            logger.error("%s: cancelling a goal accepted too late failed: %s", self._name, error)
        elif not cancel_future.result().goals_canceling:
            logger.error("%s: the robot side refused to cancel a goal accepted too late", self._name)

    def _on_result(self, result_future: Any) -> None:
        error = result_future.exception()
        if error is not None:
            self.status.set_exception(BridgeError(f"{self._name}: result request failed: {error}"))
            return
        wrapped = result_future.result()
        result = wrapped.result
        status = _STATUS_NAMES.get(wrapped.status, str(wrapped.status))
        success = wrapped.status == GoalStatus.STATUS_SUCCEEDED and bool(getattr(result, "success", True))
        error_code = "" if success else (str(getattr(result, "error_code", "")) or status)
        message = str(getattr(result, "message", ""))
        self.status.set_finished(ActionOutcome(success, error_code, message, status, result))


class ActionCaller:
    """A client of one action server (`action_type` at `action_name`), usable from any thread."""

    def __init__(self, runtime: RosRuntime, action_type: type, action_name: str) -> None:
        self._runtime = runtime
        self.action_type = action_type
        self.action_name = action_name
        self._open_goals: set[ActionGoal] = set()
        self._open_lock = threading.Lock()
        self._client: ActionClient = runtime.call(
            lambda: runtime.own(ActionClient(runtime.node, action_type, action_name))
        )
        runtime.add_end_listener(self._abandon_open_goals)

    def is_ready(self) -> bool:
        return bool(self._runtime.call(self._client.server_is_ready))

    def wait_for_server(self, timeout_s: float = 10.0) -> None:
        """Return once a live server answers; raise ServerUnavailable naming it otherwise."""
        deadline = time.monotonic() + timeout_s
        while True:
            if self.is_ready() and self.answers(min(1.0, max(0.1, deadline - time.monotonic()))):
                return
            if time.monotonic() >= deadline:
                raise ServerUnavailable(
                    f"action server {self.action_name} ({self.action_type.__name__}) "
                    f"not available after {timeout_s:.1f} s; is the robot side running in this ROS domain?"
                )
            time.sleep(0.05)

    def answers(self, timeout_s: float = 2.0) -> bool:
        """Whether a live server answers a request now: a cancel request for a goal id nobody
        sent (the server answers "unknown goal" and cancels nothing).

        Why not `is_ready`: a server killed with SIGKILL stays discovered until its DDS lease
        ends, so `is_ready` holds at once after a restart, and a goal sent then reached only the
        dead server and was never answered. A server that answers is matched; its goal service,
        discovered with it, is too."""
        answered: concurrent.futures.Future = concurrent.futures.Future()

        def ask_on_ros_thread() -> None:
            request = cancel_nobodys_goal(self._client)
            request.add_done_callback(lambda done: _copy_ros_future(done, answered))

        self._runtime.call(ask_on_ros_thread)
        try:
            answered.result(timeout=timeout_s)
        except concurrent.futures.TimeoutError:
            return False
        return True

    def send(self, goal: Any, on_feedback: Callable[[GoalProgress], None] | None = None) -> ActionGoal:
        """Send `goal`; returns at once with its status (acceptance and result come later).
        Raises BridgeError if the ROS thread could not take the request."""
        over_ros = _GoalOverRos(self._runtime, self.action_name)
        if on_feedback is not None:
            over_ros.status.add_progress_listener(on_feedback)
        with self._open_lock:
            self._open_goals.add(over_ros.status)
        over_ros.status.add_callback(self._forget)

        def send_on_ros_thread() -> None:
            response_future = self._client.send_goal_async(goal, feedback_callback=over_ros.on_feedback)
            response_future.add_done_callback(over_ros.on_goal_response)

        try:
            self._runtime.call(send_on_ros_thread)
        except BridgeError as error:
            # Reported as not sent: should it have gone out after all (the ROS thread took the call
            # but did not finish it in time), its acceptance cancels it, as for any withdrawn goal.
            over_ros.status.withdraw(f"the goal could not be sent: {error}")
            raise
        return over_ros.status

    def run(
        self,
        goal: Any,
        timeout_s: float,
        on_feedback: Callable[[GoalProgress], None] | None = None,
        accept_timeout_s: float = 10.0,
    ) -> ActionOutcome:
        """Send, wait for acceptance and for the outcome; cancel the goal if it times out. A goal
        not accepted within `accept_timeout_s` is withdrawn (`ActionGoal.wait_accepted`)."""
        status = self.send(goal, on_feedback)
        status.wait_accepted(accept_timeout_s)
        try:
            return status.result(timeout_s)
        except BridgeTimeout:
            status.cancel()
            raise

    def destroy(self) -> None:
        self._runtime.call(self._client.destroy)

    def _forget(self, goal: ActionGoal) -> None:
        with self._open_lock:
            self._open_goals.discard(goal)

    def _abandon_open_goals(self, reason: str) -> None:
        """The runtime ended: no answer can reach a goal still open, so end each with GoalAbandoned
        now rather than leave its waiter to its timeout (a step's is 10 minutes)."""
        with self._open_lock:
            goals = list(self._open_goals)
        for goal in goals:
            goal.abort(f"no answer can come: {reason}")


def cancel_nobodys_goal(client: ActionClient) -> Any:
    """Send a cancel request for a goal id nobody sent; returns its rclpy future. A live server whose
    services have matched this client answers it ("unknown goal") and cancels nothing: the probe of
    `ActionCaller.answers`. Call on the thread that spins the client's node."""
    # rclpy offers cancel requests only through a goal handle; this one was never sent
    nobodys_goal = ClientGoalHandle(client, UUID(uuid=list(uuid.uuid4().bytes)), None)
    return client._cancel_goal_async(nobodys_goal)


def _copy_ros_future(ros_future: Any, target: concurrent.futures.Future) -> None:
    """Hand an rclpy future's value or exception over to a concurrent.futures future."""
    error = ros_future.exception()
    if error is not None:
        target.set_exception(error)
    else:
        target.set_result(ros_future.result())


__all__ = ["ActionCaller", "ActionGoal", "ActionOutcome", "GoalProgress"]
