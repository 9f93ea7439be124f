"""The status of one sent action goal: one contract for every caller (SiLA glue, Bluesky, tests).

Theory of operation (after ophyd's `StatusBase`):

An `ActionGoal` is created by the back end that sends the goal - `ActionCaller.send` in the ROS
bridge, the in-memory fake robot in tests - and handed to the caller at once. It goes from
pending to accepted (or rejected) to finished, and it finishes exactly once, in one of two ways:

- with an `ActionOutcome`: the robot side answered. The answer may be a success or not (rejected,
  ABORTED with an error code, CANCELED); `wait()` returns, `exception()` is None, and `success`
  says whether the robot did it. Callers turn error codes into their own errors.
- with an exception (a `BridgeError`): no answer came - the request failed on the way, or the
  wait was given up with `abort()`. `wait()` and `result()` raise it.

Who may finish a status: its creator only - `set_accepted`, `set_rejected`, `update_progress`,
`set_finished` and `set_exception` are the creator's; for `ActionCaller` they run on the ROS
thread, from rclpy's callbacks. Two exceptions, both for a recipient that stops waiting:
- `abort(reason)`, for whoever knows that the robot side is gone and will never answer (the
  deployment's supervisor, through `RobotController.abort_active_goal`); it finishes the goal with
  `GoalAbandoned` and sends nothing;
- `withdraw(reason)`, which `wait_accepted` calls when no acceptance came in time: it asks the
  creator to cancel the goal (at once if the robot side accepted it meanwhile, else as soon as a
  late acceptance arrives, so a goal reported as failed never runs unnoticed), and finishes the
  goal with `BridgeTimeout`.
The recipient otherwise reads, waits, listens, and may ask to `cancel()`: a cancelled goal is
finished by its creator when the robot side confirms (outcome status CANCELED), not by the
canceller.

Completion is idempotent and atomic: the first of set_finished / set_rejected / set_exception /
abort / withdraw wins, under the goal's lock, so exactly one end is recorded and the callbacks run
once, on the thread of that first end (the ROS thread, or the supervisor's after `abort`); later
ends change nothing, return False and are logged at debug level. Unlike ophyd (which raises
InvalidState on a second completion) they never raise, because they run in rclpy done-callbacks,
where an exception would end the ROS executor thread, and a late robot answer racing an `abort`
is normal, not a bug.

Callbacks: `add_callback(fn)` calls `fn(goal)` exactly once, on the thread that finished the goal
(the ROS thread; the supervisor's thread after `abort`), or at once on the calling thread if the
goal has already finished. Keep them short; an exception in one is logged, never propagated.

Progress: `progress` is the robot side's latest feedback; its fraction done (0..1) never goes down
(`labware_model.progress.MonotonicProgress`) and becomes 1 ("done") when the goal succeeds. Progress
listeners are called on every feedback, on the thread that delivers it (the ROS thread for
`ActionCaller`); feedback that arrives after the end is dropped.

Waits: every wait takes a finite timeout and raises BridgeTimeout when it passes.

Threads: every method is thread-safe (one lock). Waiting methods must not be called on the
thread that finishes the goal (for `ActionCaller`: never on the ROS thread).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ros_bridge.errors import BridgeError, BridgeTimeout, GoalAbandoned, GoalRejected
from ros_bridge.progress import GoalProgress, MonotonicProgress

logger = logging.getLogger(__name__)

CancelRequest = Callable[[float], bool]
"""The creator's way to ask the robot side to cancel: called with a timeout in s, returns True
if the robot side agreed. Runs on the canceller's thread."""


@dataclass(frozen=True)
class ActionOutcome:
    """How the robot side answered a goal. `error_code` is empty exactly when `success` is true;
    `status` is the ROS goal status (SUCCEEDED, ABORTED, CANCELED) or REJECTED."""

    success: bool
    error_code: str
    message: str
    status: str
    result: Any = None


class ActionGoal:
    """A sent goal: acceptance, progress, and an outcome or an exception, with waits and callbacks."""

    def __init__(self, action_name: str, cancel_request: CancelRequest | None = None) -> None:
        self.action_name = action_name
        self.sent_at = time.monotonic()
        self._cancel_request = cancel_request
        self._lock = threading.Lock()
        self._acceptance_known = threading.Event()
        self._finished = threading.Event()
        self._accepted: bool | None = None
        self._outcome: ActionOutcome | None = None
        self._exception: BridgeError | None = None
        self._fraction = MonotonicProgress()
        self._progress = GoalProgress()
        self._progress_listeners: list[Callable[[GoalProgress], None]] = []
        self._callbacks: list[Callable[[ActionGoal], None]] = []

    # --- reading ---

    @property
    def done(self) -> bool:
        """True once the goal has finished, with an outcome or an exception."""
        return self._finished.is_set()

    @property
    def success(self) -> bool:
        """True once the robot side reported that it reached the goal."""
        with self._lock:
            return self._outcome is not None and self._outcome.success

    @property
    def accepted(self) -> bool | None:
        """True once the robot side accepted the goal, False if it rejected it, None while unknown
        (or if the goal ended with an exception before an answer came)."""
        with self._lock:
            return self._accepted

    @property
    def outcome(self) -> ActionOutcome | None:
        """The robot side's answer, None while running or if the goal ended with an exception."""
        with self._lock:
            return self._outcome

    @property
    def progress(self) -> GoalProgress:
        with self._lock:
            return self._progress

    # --- waiting (never on the thread that finishes the goal) ---

    def wait_accepted(self, timeout_s: float = 10.0) -> None:
        """Return once the robot side accepted the goal; raise GoalRejected if it refused it, or the
        goal's exception. If no answer came within `timeout_s`, the goal is withdrawn (see
        `withdraw`: cancelled should the robot side accept it later) and BridgeTimeout raised."""
        if not self._acceptance_known.wait(_finite(timeout_s)):
            self.withdraw(f"no answer to the goal request within {timeout_s:.1f} s")
            withdrawn = self.exception()
            if withdrawn is not None:
                raise withdrawn
        with self._lock:
            accepted, error = self._accepted, self._exception
        if accepted is None and error is not None:
            raise error
        if not accepted:
            raise GoalRejected(f"{self.action_name}: the action server rejected the goal")

    def wait(self, timeout_s: float) -> None:
        """Return once the goal has finished with an outcome (successful or not); raise its
        exception if it ended with one, BridgeTimeout if it is still running after `timeout_s`."""
        if not self._finished.wait(_finite(timeout_s)):
            raise BridgeTimeout(f"{self.action_name}: no result within {timeout_s:.1f} s")
        if self._exception is not None:
            raise self._exception

    def result(self, timeout_s: float) -> ActionOutcome:
        """`wait(timeout_s)`, then the outcome. A rejected goal is an unsuccessful outcome."""
        self.wait(timeout_s)
        assert self._outcome is not None  # finished without an exception
        return self._outcome

    def exception(self, timeout_s: float = 0.0) -> BridgeError | None:
        """Wait for the end like `wait` (by default not at all: for a goal known to have ended);
        the exception the goal ended with, None if it was answered."""
        if not self._finished.wait(_finite(timeout_s)):
            raise BridgeTimeout(f"{self.action_name}: not finished within {timeout_s:.1f} s")
        return self._exception

    # --- watching ---

    def add_callback(self, callback: Callable[[ActionGoal], None]) -> None:
        """Call `callback(goal)` once when the goal finishes (at once if it already has)."""
        with self._lock:
            if not self._finished.is_set():
                self._callbacks.append(callback)
                return
        self._run_callback(callback)

    def add_progress_listener(self, listener: Callable[[GoalProgress], None]) -> None:
        """Call `listener(progress)` on every feedback from now on (on the thread delivering it)."""
        with self._lock:
            self._progress_listeners.append(listener)

    def cancel(self, timeout_s: float = 5.0) -> bool:
        """Ask the robot side to cancel; True if it agreed (or the goal had not been accepted yet).
        False if the goal has already finished or its creator offers no way to cancel. The goal
        finishes when the robot side answers, usually with outcome status CANCELED."""
        if self.done or self._cancel_request is None:
            return False
        return self._cancel_request(timeout_s)

    # --- finishing: the creator's (plus `abort`); never raise ---

    def set_accepted(self) -> bool:
        """The robot side accepted the goal. False (and no change) if acceptance was already known."""
        with self._lock:
            if self._acceptance_known.is_set():
                logger.debug("%s: acceptance ignored, already known", self.action_name)
                return False
            self._accepted = True
            self._acceptance_known.set()
        return True

    def set_rejected(self, message: str = "") -> bool:
        """The robot side refused the goal: finish with a REJECTED outcome."""
        reason = message or f"{self.action_name}: goal rejected by the server"
        return self._finish(ActionOutcome(False, "REJECTED", reason, "REJECTED"), None, accepted=False)

    def update_progress(self, progress: float, phase: str, remaining_time_s: float) -> bool:
        """Take one feedback (fraction done 0..1, phase, remaining s) and tell the listeners.
        Returns False, dropping it, once the goal has finished."""
        with self._lock:
            if self._finished.is_set():
                return False
            self._progress = GoalProgress(
                progress=self._fraction.advance(progress),
                phase=phase,
                remaining_time_s=max(0.0, remaining_time_s),
                feedback_count=self._progress.feedback_count + 1,
            )
            shown, listeners = self._progress, list(self._progress_listeners)
        for listener in listeners:
            try:
                listener(shown)
            except Exception:  # noqa: BLE001 - a broken listener must not stop the ROS executor
                logger.exception("%s: progress listener failed", self.action_name)
        return True

    def set_finished(self, outcome: ActionOutcome) -> bool:
        """The robot side answered with `outcome`. False if the goal had already finished."""
        return self._finish(outcome, None, accepted=True)

    def set_exception(self, error: BridgeError) -> bool:
        """No answer will come: finish with `error`. False if the goal had already finished."""
        finished = self._finish(None, error, accepted=None)
        if finished:
            logger.warning("%s", error)
        return finished

    def abort(self, reason: str) -> bool:
        """Stop waiting for a robot side that is gone: finish with GoalAbandoned(`reason`). For the
        supervisor; sends nothing to the robot side. False if the goal had already finished."""
        return self.set_exception(GoalAbandoned(f"{self.action_name}: {reason}"))

    def withdraw(self, reason: str, cancel_timeout_s: float = 5.0) -> bool:
        """Give the goal up before it was accepted: finish it with BridgeTimeout(`reason`), so
        feedback and a result that still come are dropped, and ask the creator to cancel it: at
        once if the robot side accepted it meanwhile (waiting up to `cancel_timeout_s` for the
        request to go out), else as soon as a late acceptance arrives. False, doing nothing, if
        the goal had already finished."""
        if self.done:
            return False
        if self._cancel_request is not None:
            try:
                self._cancel_request(cancel_timeout_s)
            except BridgeError as cancel_error:
                logger.warning("%s: cancelling the withdrawn goal failed: %s", self.action_name, cancel_error)
        return self.set_exception(
            BridgeTimeout(
                f"{self.action_name}: {reason}; the goal was withdrawn (cancelled should the robot side "
                "accept it later)"
            )
        )

    # --- helpers ---

    def _finish(
        self, outcome: ActionOutcome | None, error: BridgeError | None, accepted: bool | None
    ) -> bool:
        with self._lock:
            if self._finished.is_set():
                logger.debug(
                    "%s: a second end ignored (%s); the goal already ended: %s",
                    self.action_name,
                    error or outcome,
                    self._exception or self._outcome,
                )
                return False
            self._outcome, self._exception = outcome, error
            if not self._acceptance_known.is_set():
                self._accepted = accepted
                self._acceptance_known.set()
            listeners: list[Callable[[GoalProgress], None]] = []
            if outcome is not None and outcome.success:  # done is 100 %: the listeners hear it too
                self._progress = GoalProgress(
                    self._fraction.advance(1.0), "done", 0.0, self._progress.feedback_count
                )
                listeners = list(self._progress_listeners)
            final_progress = self._progress
            callbacks, self._callbacks = self._callbacks, []
            self._finished.set()
        for listener in listeners:
            try:
                listener(final_progress)
            except Exception:  # noqa: BLE001 - a broken listener must not stop the finishing thread
                logger.exception("%s: progress listener failed", self.action_name)
        for callback in callbacks:
            self._run_callback(callback)
        return True

    def _run_callback(self, callback: Callable[[ActionGoal], None]) -> None:
        try:
            callback(self)
        except Exception:  # noqa: BLE001 - a broken callback must not stop the thread finishing the goal
            logger.exception("%s: completion callback failed", self.action_name)

    def __repr__(self) -> str:
        with self._lock:
            if self._exception is not None:
                state = f"failed: {self._exception}"
            elif self._outcome is not None:
                state = f"{self._outcome.status} {self._outcome.error_code}".strip()
            else:
                state = {None: "pending", True: "accepted", False: "rejected"}[self._accepted]
        return f"ActionGoal({self.action_name}, {state}, progress={self._progress.progress:.2f})"


def _finite(timeout_s: float) -> float:
    """A wait's bound: a number of seconds, never None (which would wait forever)."""
    if timeout_s is None:
        raise TypeError("a wait on a goal needs a timeout in seconds, not None")
    return max(0.0, float(timeout_s))
