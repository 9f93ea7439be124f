"""One running action goal on the robot side: feedback, cancel, and waiting on sim Motions.

Execute callbacks (executor threads) describe a goal as a sequence of steps; each step either
runs a job on the sim thread or starts a Motion there and waits for it while sending feedback
at `feedback_hz`. Failures are raised as `ActionAbort(code, message)` and turned into a result
by the caller. Lives on: an rclpy executor thread (one per goal).
"""

from __future__ import annotations

import concurrent.futures
import logging
import threading
import time
from collections.abc import Callable
from typing import Any

from labware_interfaces.msg import ErrorCodes

from labware_model.progress import MonotonicProgress
from tiago_sim.sim_node.sim_thread import SimThread

log = logging.getLogger(__name__)

# Longest wait between looks at cancel requests and feedback while a job or motion runs; the end
# of either wakes the waiting thread at once.
_POLL_S = 0.02


class ActionAbort(Exception):
    """A goal ends unsuccessfully with a code of labware_interfaces/msg/ErrorCodes and a reason."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message


class MotionSlot:
    """Allows one motion-producing goal at a time across all action servers of the node."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.owner = ""

    def acquire(self, owner: str) -> None:
        if not self._lock.acquire(blocking=False):
            raise ActionAbort(ErrorCodes.BUSY, f"busy with {self.owner or 'another goal'}")
        self.owner = owner

    def release(self) -> None:
        self.owner = ""
        self._lock.release()


class ActionRun:
    """Feedback and cancel handling for one goal (lives on its executor thread)."""

    def __init__(
        self,
        goal_handle: Any,
        feedback_type: type,
        sim_thread: SimThread,
        *,
        feedback_hz: float = 5.0,
        on_motion: Callable[[Any], None] | None = None,
    ) -> None:
        self.goal_handle = goal_handle
        self.feedback_type = feedback_type
        self.sim_thread = sim_thread
        self.feedback_period_s = 1.0 / max(feedback_hz, 2.0)
        self.on_motion = on_motion
        self.progress = 0.0
        self.phase = "starting"
        self.remaining_s = 0.0
        self._last_feedback = 0.0
        self._published = MonotonicProgress()  # a drive planning a longer way round must not pull it back

    def canceled(self) -> bool:
        return bool(self.goal_handle.is_cancel_requested)

    def check_cancel(self) -> None:
        if self.canceled():
            raise ActionAbort(ErrorCodes.CANCELED, "canceled on request")

    def feedback(self, progress: float, phase: str, remaining_s: float, *, force: bool = False) -> None:
        """Publish feedback, at most every feedback period unless forced."""
        self.progress, self.phase, self.remaining_s = progress, phase, remaining_s
        now = time.monotonic()
        if not force and now - self._last_feedback < self.feedback_period_s:
            return
        self._last_feedback = now
        message = self.feedback_type()
        message.progress = float(self._published.advance(progress))
        message.phase = phase
        message.remaining_time_s = float(max(remaining_s, 0.0))
        try:
            self.goal_handle.publish_feedback(message)
        except Exception:  # noqa: BLE001 - feedback is best effort (goal may be finishing)
            log.debug("feedback not published", exc_info=True)

    def sim(self, job: Callable[[Any], Any], timeout_s: float = 60.0) -> Any:
        """Run a job on the sim thread and wait, sending feedback while waiting."""
        future = self.sim_thread.call(job)
        deadline = time.monotonic() + timeout_s
        while True:
            try:
                return future.result(timeout=_POLL_S)  # returns the moment the job is done
            except concurrent.futures.TimeoutError:
                pass
            if time.monotonic() > deadline or self.sim_thread.stopped:
                raise ActionAbort(ErrorCodes.INTERNAL, "simulation did not answer in time")
            self.feedback(self.progress, self.phase, self.remaining_s)

    def stop(self, motions: list[Any]) -> None:
        """Cancel the motions among `motions` still running and wait until they stand: a goal
        that ends (cancelled or failed) stops what it started beside the motion it followed."""
        running = [motion for motion in motions if motion is not None and not motion.done]
        for motion in running:
            self.sim_thread.call(lambda _sim, motion=motion: motion.cancel())
        for motion in running:
            motion.finished.wait(5.0)

    def run_motion(
        self,
        start: Callable[[Any], Any],
        *,
        span: tuple[float, float] = (0.0, 1.0),
        later_s: float = 0.0,
        timeout_s: float = 600.0,
    ) -> Any:
        """Start a Motion on the sim thread and follow it until done.

        Progress of the motion is mapped into `span` of the goal's progress; `later_s` is the
        estimated time of the steps after this one (added to the remaining time). A cancel
        request cancels the motion, waits until it has stopped and raises CANCELED. A failed
        motion raises its own error code and message.
        """
        self.check_cancel()
        motion = self.sim(start)
        if self.on_motion is not None:
            self.on_motion(motion)
        low, high = span
        sim_deadline = self.sim_thread.sim_time + timeout_s
        cancel_sent = False
        while not motion.done:
            if self.sim_thread.stopped:
                raise ActionAbort(ErrorCodes.INTERNAL, "simulation stopped")
            if self.canceled() and not cancel_sent:
                self.sim_thread.call(lambda _sim: motion.cancel())
                cancel_sent = True
            if self.sim_thread.sim_time > sim_deadline and not cancel_sent:
                self.sim_thread.call(lambda _sim: motion.cancel())
                cancel_sent = True
            fraction = float(motion.progress)
            self.feedback(
                low + (high - low) * fraction, str(motion.phase), float(motion.remaining_s) + later_s
            )
            motion.finished.wait(_POLL_S)
        if cancel_sent and self.canceled():
            raise ActionAbort(ErrorCodes.CANCELED, f"canceled during {motion.name}: stopped safely")
        if cancel_sent:
            raise ActionAbort(ErrorCodes.MOTION_FAILED, f"{motion.name} timed out after {timeout_s:.0f} s")
        if not motion.success:
            raise ActionAbort(motion.error_code or ErrorCodes.MOTION_FAILED, motion.message or motion.name)
        self.feedback(high, str(motion.phase), later_s)
        return motion
