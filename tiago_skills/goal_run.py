"""One running action goal on the robot side: feedback, cancel, and waiting on the hardware.

Execute callbacks (executor threads) describe a goal as a sequence of steps; each step reads the
hardware or starts a command on it (an Execution) and waits for it while sending feedback at
`feedback_hz`. Failures are raised as `ActionAbort(code, message)` and turned into a result by the
caller. The hardware is the port (robot_port): the same code drives the simulator and a robot.
Lives on: an rclpy executor thread (one per goal).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any

from labware_interfaces.msg import ErrorCodes

from labware_model.progress import MonotonicProgress
from robot_port.execution import Execution
from robot_port.hardware import HardwareUnavailable, RobotHardware

log = logging.getLogger(__name__)

# Longest wait between looks at cancel requests and feedback while a command runs; the end of the
# command wakes the waiting thread at once.
_POLL_S = 0.02


class ActionAbort(Exception):
    """A goal ends unsuccessfully with a code of labware_interfaces/msg/ErrorCodes and a reason."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message


class MotionSlot:
    """Allows one motion-producing goal at a time across all action servers of the robot."""

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


class GoalRun:
    """Feedback and cancel handling for one goal (lives on its executor thread)."""

    def __init__(
        self, goal_handle: Any, feedback_type: type, hardware: RobotHardware, *, feedback_hz: float = 5.0
    ) -> None:
        self.goal_handle = goal_handle
        self.feedback_type = feedback_type
        self.hardware = hardware
        self.feedback_period_s = 1.0 / max(feedback_hz, 2.0)
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

    def read(self, reading: Callable[[RobotHardware], Any]) -> Any:
        """A reading of the hardware; a hardware that stopped answering ends the goal (INTERNAL)."""
        try:
            return reading(self.hardware)
        except HardwareUnavailable as error:
            raise ActionAbort(ErrorCodes.INTERNAL, str(error)) from None

    def stop(self, executions: list[Execution | None]) -> None:
        """Cancel those of `executions` still running and wait until they stand: a goal that ends
        (cancelled or failed) stops what it started beside the command it followed."""
        running = [execution for execution in executions if execution is not None and not execution.done]
        for execution in running:
            execution.cancel()
        for execution in running:
            execution.wait(5.0)

    def follow(
        self,
        start: Callable[[RobotHardware], Execution] | Execution,
        *,
        span: tuple[float, float] = (0.0, 1.0),
        later_s: float = 0.0,
        timeout_s: float = 600.0,
        while_running: Callable[[Execution], None] | None = None,
    ) -> Execution:
        """Start a command on the hardware (or take one already started) and follow it until done.

        Its progress is mapped into `span` of the goal's progress; `later_s` is the estimated time
        of the steps after this one (added to the remaining time). A cancel request cancels the
        command, waits until it has stopped and raises CANCELED; after `timeout_s` of robot time it
        is cancelled and fails (MOTION_FAILED). A failed command raises its own code and message.
        `while_running` is called with the command at every poll (to start something beside it).
        """
        self.check_cancel()
        execution = start if isinstance(start, Execution) else self.read(start)
        low, high = span
        deadline = self.read(lambda hardware: hardware.now()) + timeout_s
        cancel_sent = timed_out = False
        while not execution.done:
            if not cancel_sent and (self.canceled() or self.read(lambda hardware: hardware.now()) > deadline):
                timed_out = not self.canceled()
                execution.cancel()
                cancel_sent = True
            fraction = float(execution.progress)
            self.feedback(
                low + (high - low) * fraction, str(execution.phase), float(execution.remaining_s) + later_s
            )
            if while_running is not None:
                while_running(execution)
            execution.wait(_POLL_S)
        if cancel_sent and not timed_out:
            raise ActionAbort(ErrorCodes.CANCELED, f"canceled during {execution.name}: stopped safely")
        if timed_out:
            raise ActionAbort(ErrorCodes.MOTION_FAILED, f"{execution.name} timed out after {timeout_s:.0f} s")
        if not execution.success:
            raise ActionAbort(
                execution.error_code or ErrorCodes.MOTION_FAILED, execution.message or execution.name
            )
        self.feedback(high, str(execution.phase), later_s)
        return execution
