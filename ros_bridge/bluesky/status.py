"""An Ophyd status that follows one ROS 2 action goal: progress to watchers, result to callbacks.

Bluesky waits on Ophyd status objects; our robot answers with ROS 2 action goals
(`ros_bridge.goal_status.ActionGoal`). `ActionStatus` joins the two: action feedback becomes
MoveStatus-style watcher calls (so bluesky's ProgressBar draws a bar in percent), the action's
outcome finishes the status (or fails it with `ActionFailed`, carrying the action's error code
and message), and a failed status - timeout, or the device being stopped - cancels the goal.

It consumes the goal's status contract (ros_bridge.goal_status): a progress listener for the
watchers, a completion callback for the end; it never touches the goal's internals.

Threads: feedback and outcome arrive on the ROS thread of the `RosRuntime` (the goal's progress
listeners and callbacks run there); watchers are called there and must stay short. A status with
a timeout runs its callbacks on Ophyd's own callback thread. Cancelling never blocks the calling
thread: it is sent from a short-lived helper thread, because the ROS thread must not wait on its
own answers.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any

from ophyd.status import DeviceStatus
from ophyd.utils import InvalidState

from ros_bridge.errors import BridgeError
from ros_bridge.goal_status import ActionGoal, ActionOutcome
from ros_bridge.progress import GoalProgress

logger = logging.getLogger(__name__)

Watcher = Callable[..., None]

PERCENT = 100.0


class ActionFailed(BridgeError):
    """A robot action ended without success; `error_code` is one of labware_interfaces' ERROR_* codes."""

    def __init__(self, action_name: str, error_code: str, message: str, status: str = "") -> None:
        self.action_name = action_name
        self.error_code = error_code
        self.message = message
        self.status = status
        super().__init__(f"{action_name} failed [{error_code}]: {message}")


class ActionStatus(DeviceStatus):
    """DeviceStatus of one ROS 2 action goal; `watch` reports percent done like a MoveStatus."""

    def __init__(
        self,
        device: Any,
        goal: ActionGoal,
        *,
        label: str | None = None,
        timeout: float | None = None,
        cancel_timeout_s: float = 5.0,
    ) -> None:
        self.goal = goal
        self.label = label or goal.action_name
        self.outcome: ActionOutcome | None = None
        self._cancel_timeout_s = cancel_timeout_s
        self._cancel_lock = threading.Lock()
        self._cancel_sent = False
        self._started_at = time.monotonic()
        # The status cancels its own goal on failure (see _handle_failure); the device need not.
        super().__init__(device, timeout=timeout, call_stop_on_failure=False)
        goal.add_progress_listener(self._on_progress)
        goal.add_callback(self._on_goal_finished)

    @property
    def progress(self) -> GoalProgress:
        return self.goal.progress

    def watch(self, func: Watcher) -> None:
        """Call `func(name=, current=, initial=, target=, unit=, precision=, fraction=, ...)` on progress."""
        self._watchers.append(func)
        self._notify(func, self.goal.progress)

    def cancel_goal(self) -> None:
        """Ask the robot to cancel the goal unless it has already ended; returns at once."""
        if self.goal.done:
            return
        with self._cancel_lock:
            if self._cancel_sent:
                return
            self._cancel_sent = True
        logger.info("%s: cancelling the goal", self.label)
        threading.Thread(target=self._send_cancel, name=f"cancel-{self.label}", daemon=True).start()

    # --- Ophyd hooks ---

    def _handle_failure(self) -> None:
        super()._handle_failure()
        self.cancel_goal()

    def _settled(self) -> None:
        # Called before `done` is set: `success` is not yet true, so look at the exception.
        succeeded = self._exception is None
        for watcher in list(self._watchers):
            if succeeded:
                self._notify(watcher, GoalProgress(1.0, "done", 0.0, self.goal.progress.feedback_count))
            else:
                watcher(name=self._watcher_name(), fraction=None)

    # --- ROS thread ---

    def _on_progress(self, progress: GoalProgress) -> None:
        if self.done or self.goal.done:  # the end is reported once, when the status settles
            return
        for watcher in list(self._watchers):
            try:
                self._notify(watcher, progress)
            except Exception:  # noqa: BLE001 - a broken progress bar must not fail the goal
                logger.exception("%s: progress watcher failed", self.label)

    def _on_goal_finished(self, goal: ActionGoal) -> None:
        error: Exception | None = goal.exception()  # finished: returns at once
        if error is None:
            self.outcome = goal.outcome
            assert self.outcome is not None  # answered goals carry an outcome
            if not self.outcome.success:
                error = ActionFailed(
                    self.label, self.outcome.error_code, self.outcome.message, self.outcome.status
                )
        try:
            if error is None:
                logger.info("%s: done (%s)", self.label, self.outcome.message if self.outcome else "")
                self.set_finished()
            else:
                logger.warning("%s: %s", self.label, error)
                self.set_exception(error)
        except InvalidState:
            logger.debug("%s: the status had already ended (timeout)", self.label)

    # --- helpers ---

    def _send_cancel(self) -> None:
        try:
            agreed = self.goal.cancel(self._cancel_timeout_s)
        except BridgeError as error:
            logger.warning("%s: cancel request failed: %s", self.label, error)
            return
        if not agreed and not self.goal.done:
            logger.warning("%s: the robot refused to cancel the goal", self.label)

    def _watcher_name(self) -> str:
        device_name = getattr(self.device, "name", "")
        return f"{device_name} {self.label}".strip()

    def _notify(self, watcher: Watcher, progress: GoalProgress) -> None:
        done_fraction = min(1.0, max(0.0, progress.progress))
        watcher(
            name=self._watcher_name(),
            current=round(PERCENT * done_fraction, 1),
            initial=0.0,
            target=PERCENT,
            unit="%",
            precision=1,
            fraction=1.0 - done_fraction,
            time_elapsed=time.monotonic() - self._started_at,
            time_remaining=progress.remaining_time_s,
        )

    def __str__(self) -> str:
        # bluesky puts str(status) into the run's stop document: say why it failed.
        error = f", error={self._exception}" if self.done and self._exception is not None else ""
        return f"ActionStatus({self.label}, done={self.done}, success={self.success}{error})"

    __repr__ = __str__
