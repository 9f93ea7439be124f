"""Call a ROS 2 action from any thread: send goal, watch feedback, wait for the result, cancel.

Threads: `ActionCaller` and `ActionGoal` are used from caller threads (SiLA handlers). Every
rclpy call they make is handed to the ROS thread of a `RosRuntime`; what comes back (goal
accepted, feedback, result) is stored in `concurrent.futures.Future`s and a lock-protected
progress snapshot. Feedback listeners run on the ROS thread: keep them short.

Our actions share one feedback shape (progress 0..1, phase, remaining_time_s) and one result
shape (success, error_code, message); other fields of the result stay reachable as `result`.
"""

from __future__ import annotations

import concurrent.futures
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from action_msgs.msg import GoalStatus
from rclpy.action import ActionClient
from rclpy.action.client import ClientGoalHandle

from ros_bridge.errors import BridgeError, BridgeTimeout, GoalRejected, ServerUnavailable
from ros_bridge.runtime import RosRuntime

logger = logging.getLogger(__name__)

_STATUS_NAMES = {
    GoalStatus.STATUS_SUCCEEDED: "SUCCEEDED",
    GoalStatus.STATUS_ABORTED: "ABORTED",
    GoalStatus.STATUS_CANCELED: "CANCELED",
    GoalStatus.STATUS_UNKNOWN: "UNKNOWN",
}


@dataclass(frozen=True)
class GoalProgress:
    """The latest feedback of a goal; progress never goes down."""

    progress: float = 0.0
    phase: str = "pending"
    remaining_time_s: float = 0.0
    feedback_count: int = 0


@dataclass(frozen=True)
class ActionOutcome:
    """How a goal ended. `error_code` is empty exactly when `success` is true."""

    success: bool
    error_code: str
    message: str
    status: str
    result: Any = None


class ActionGoal:
    """A sent goal: a status object with progress, a result future and cancel."""

    def __init__(self, runtime: RosRuntime, action_name: str) -> None:
        self._runtime = runtime
        self.action_name = action_name
        self.accepted: concurrent.futures.Future[bool] = concurrent.futures.Future()
        self.outcome: concurrent.futures.Future[ActionOutcome] = concurrent.futures.Future()
        self._lock = threading.Lock()
        self._progress = GoalProgress()
        self._listeners: list[Callable[[GoalProgress], None]] = []
        self._ros_handle: ClientGoalHandle | None = None
        self._cancel_requested = False
        self.sent_at = time.monotonic()

    @property
    def progress(self) -> GoalProgress:
        with self._lock:
            return self._progress

    def add_listener(self, listener: Callable[[GoalProgress], None]) -> None:
        """Call `listener(progress)` on every feedback (on the ROS thread)."""
        with self._lock:
            self._listeners.append(listener)

    def wait_accepted(self, timeout_s: float = 10.0) -> None:
        """Return once the server accepted the goal; raise GoalRejected or BridgeTimeout."""
        try:
            accepted = self.accepted.result(timeout=timeout_s)
        except concurrent.futures.TimeoutError as error:
            raise BridgeTimeout(
                f"{self.action_name}: no answer to the goal request within {timeout_s:.1f} s"
            ) from error
        if not accepted:
            raise GoalRejected(f"{self.action_name}: the action server rejected the goal")

    def result(self, timeout_s: float | None = None) -> ActionOutcome:
        """Wait for the outcome. A rejected goal is an unsuccessful outcome, not an exception."""
        try:
            return self.outcome.result(timeout=timeout_s)
        except concurrent.futures.TimeoutError as error:
            raise BridgeTimeout(f"{self.action_name}: no result within {timeout_s:.1f} s") from error

    def cancel(self, timeout_s: float = 5.0) -> bool:
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
                f"{self.action_name}: no answer to the cancel request within {timeout_s:.1f} s"
            ) from error
        return bool(response.goals_canceling)

    # --- ROS thread only below ---

    def _on_feedback(self, feedback_message: Any) -> None:
        feedback = feedback_message.feedback
        with self._lock:
            self._progress = GoalProgress(
                progress=max(self._progress.progress, min(1.0, float(getattr(feedback, "progress", 0.0)))),
                phase=str(getattr(feedback, "phase", "")),
                remaining_time_s=max(0.0, float(getattr(feedback, "remaining_time_s", 0.0))),
                feedback_count=self._progress.feedback_count + 1,
            )
            progress, listeners = self._progress, list(self._listeners)
        for listener in listeners:
            try:
                listener(progress)
            except Exception:  # noqa: BLE001 - a broken listener must not stop the executor
                logger.exception("%s: feedback listener failed", self.action_name)

    def _on_goal_response(self, response_future: Any) -> None:
        error = response_future.exception()
        if error is not None:
            self._finish_with_error(BridgeError(f"{self.action_name}: goal request failed: {error}"))
            return
        ros_handle: ClientGoalHandle = response_future.result()
        if not ros_handle.accepted:
            self.accepted.set_result(False)
            self.outcome.set_result(
                ActionOutcome(
                    False, "REJECTED", f"{self.action_name}: goal rejected by the server", "REJECTED"
                )
            )
            return
        with self._lock:
            self._ros_handle = ros_handle
            cancel_now = self._cancel_requested
        self.accepted.set_result(True)
        ros_handle.get_result_async().add_done_callback(self._on_result)
        if cancel_now:
            ros_handle.cancel_goal_async()

    def _on_result(self, result_future: Any) -> None:
        error = result_future.exception()
        if error is not None:
            self._finish_with_error(BridgeError(f"{self.action_name}: result request failed: {error}"))
            return
        wrapped = result_future.result()
        result = wrapped.result
        status = _STATUS_NAMES.get(wrapped.status, str(wrapped.status))
        success = wrapped.status == GoalStatus.STATUS_SUCCEEDED and bool(getattr(result, "success", True))
        error_code = "" if success else (str(getattr(result, "error_code", "")) or status)
        message = str(getattr(result, "message", ""))
        if success:
            with self._lock:
                self._progress = GoalProgress(1.0, "done", 0.0, self._progress.feedback_count)
        self.outcome.set_result(ActionOutcome(success, error_code, message, status, result))

    def _finish_with_error(self, error: BridgeError) -> None:
        logger.warning("%s", error)
        if not self.accepted.done():
            self.accepted.set_exception(error)
        if not self.outcome.done():
            self.outcome.set_exception(error)


class ActionCaller:
    """A client of one action server (`action_type` at `action_name`), usable from any thread."""

    def __init__(self, runtime: RosRuntime, action_type: type, action_name: str) -> None:
        self._runtime = runtime
        self.action_type = action_type
        self.action_name = action_name
        self._client: ActionClient = runtime.call(
            lambda: runtime.own(ActionClient(runtime.node, action_type, action_name))
        )

    def is_ready(self) -> bool:
        return bool(self._runtime.call(self._client.server_is_ready))

    def wait_for_server(self, timeout_s: float = 10.0) -> None:
        """Return once the server is discovered; raise ServerUnavailable naming it otherwise."""
        deadline = time.monotonic() + timeout_s
        while True:
            if self.is_ready():
                return
            if time.monotonic() >= deadline:
                raise ServerUnavailable(
                    f"action server {self.action_name} ({self.action_type.__name__}) "
                    f"not available after {timeout_s:.1f} s; is the robot side running in this ROS domain?"
                )
            time.sleep(0.05)

    def send(self, goal: Any, on_feedback: Callable[[GoalProgress], None] | None = None) -> ActionGoal:
        """Send `goal`; returns at once with a handle (acceptance and result come later)."""
        handle = ActionGoal(self._runtime, self.action_name)
        if on_feedback is not None:
            handle.add_listener(on_feedback)

        def send_on_ros_thread() -> None:
            response_future = self._client.send_goal_async(goal, feedback_callback=handle._on_feedback)
            response_future.add_done_callback(handle._on_goal_response)

        self._runtime.call(send_on_ros_thread)
        return handle

    def run(
        self,
        goal: Any,
        timeout_s: float,
        on_feedback: Callable[[GoalProgress], None] | None = None,
        accept_timeout_s: float = 10.0,
    ) -> ActionOutcome:
        """Send, wait for acceptance and for the outcome; cancel the goal if it times out."""
        handle = self.send(goal, on_feedback)
        handle.wait_accepted(accept_timeout_s)
        try:
            return handle.result(timeout_s)
        except BridgeTimeout:
            handle.cancel()
            raise

    def destroy(self) -> None:
        self._runtime.call(self._client.destroy)


def _copy_ros_future(ros_future: Any, target: concurrent.futures.Future) -> None:
    """Hand an rclpy future's value or exception over to a concurrent.futures future."""
    error = ros_future.exception()
    if error is not None:
        target.set_exception(error)
    else:
        target.set_result(ros_future.result())
