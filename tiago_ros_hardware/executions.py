"""The port's Execution (robot_port.execution) for what the adapter starts over ROS: action goals sent
together (a trajectory on several controllers, a navigation goal), and loops the adapter runs itself
(a velocity command held for a while, a drive closed on odometry).

Why here and not in the skills: the skills read every command the same way (done, success, a code of
labware_interfaces/msg/ErrorCodes, progress, the time left, cancel), whatever runs it.

Threads: goals answer on the node's executor threads; readers and `cancel` on any thread.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from action_msgs.msg import GoalStatus

Clock = Callable[[], float]


class _Outcome:
    """Done, success, error code and message, set once; shared by the executions below."""

    def __init__(
        self, name: str, clock: Clock, duration_s: float, on_end: Callable[[], None] | None = None
    ) -> None:
        self.name = name
        self._on_end = on_end  # called once, as the command ends and before any reading of it
        self._clock = clock
        self._started_s = clock()
        self._duration_s = max(duration_s, 1e-3)
        self._finished = threading.Event()
        self._lock = threading.Lock()
        self.success = False
        self.error_code = ""
        self.message = ""
        self.phase = "starting"
        self.result: dict[str, Any] = {}

    @property
    def done(self) -> bool:
        return self._finished.is_set()

    @property
    def progress(self) -> float:
        if self.done:
            return 1.0 if self.success else 0.0
        return min(max((self._clock() - self._started_s) / self._duration_s, 0.0), 0.99)

    @property
    def remaining_s(self) -> float:
        return 0.0 if self.done else max(self._started_s + self._duration_s - self._clock(), 0.0)

    def wait(self, timeout_s: float) -> bool:
        return self._finished.wait(timeout_s)

    def _ending(self) -> None:
        on_end, self._on_end = self._on_end, None
        if on_end is not None:
            on_end()

    def _end(self, success: bool, code: str = "", message: str = "") -> None:
        self._ending()
        with self._lock:
            if self._finished.is_set():
                return
            self.success, self.error_code = success, "" if success else code
            self.message = message or ("done" if success else code)
            self.phase = "done" if success else "failed"
            self._finished.set()


class FailedExecution(_Outcome):
    """A command refused before it started (busy, a bad goal, no interface)."""

    def __init__(self, name: str, code: str, message: str) -> None:
        super().__init__(name, lambda: 0.0, 0.0)
        self._end(False, code, message)

    def cancel(self) -> None:
        pass


class GoalsExecution(_Outcome):
    """Goals (action name, client, goal) to several action servers at once, done when every one
    has ended; success when all succeeded. `failure_code` names a goal that aborted
    (MOTION_FAILED, NAVIGATION_FAILED); a rejected goal is BAD_GOAL, a cancelled one CANCELED.
    `on_success` may read the robot once all succeeded and returns the execution's `result`."""

    def __init__(
        self,
        name: str,
        goals: list[tuple[str, Any, Any]],
        clock: Clock,
        duration_s: float,
        failure_code: str,
        on_success: Callable[[], dict[str, Any]] | None = None,
        on_end: Callable[[], None] | None = None,
    ) -> None:
        super().__init__(name, clock, duration_s, on_end)
        self.phase = "moving"
        self._failure_code = failure_code
        self._on_success = on_success
        self._handles: list[Any] = []
        self._waiting = len(goals)
        self._failures: list[tuple[str, str]] = []
        self._cancel_requested = False
        for action, client, goal in goals:
            future = client.send_goal_async(goal)
            future.add_done_callback(lambda f, action=action: self._accepted(action, f))

    def _accepted(self, action: str, future: Any) -> None:
        handle = future.result()
        if handle is None or not handle.accepted:
            self._ended(action, GoalStatus.STATUS_ABORTED, None, rejected=True)
            return
        with self._lock:
            self._handles.append(handle)
            cancel = self._cancel_requested
        if cancel:
            handle.cancel_goal_async()
        handle.get_result_async().add_done_callback(
            lambda f: self._ended(action, f.result().status, f.result().result)
        )

    def _ended(self, action: str, status: int, result: Any, rejected: bool = False) -> None:
        with self._lock:
            self._waiting -= 1
            if rejected:
                self._failures.append(("BAD_GOAL", f"{action} rejected the goal"))
            elif status == GoalStatus.STATUS_CANCELED:
                self._failures.append(("CANCELED", "canceled"))
            elif status != GoalStatus.STATUS_SUCCEEDED:
                why = (
                    getattr(result, "error_string", "")
                    or getattr(result, "error_msg", "")
                    or getattr(result, "error", "")
                    or f"status {status}"
                )
                self._failures.append((self._failure_code, f"{action}: {why}"))
            left, failures = self._waiting, list(self._failures)
        if left > 0:
            return
        if failures:
            self._end(False, *failures[0])
            return
        self._ending()
        try:
            self.result = self._on_success() if self._on_success is not None else {}
        except Exception as error:  # noqa: BLE001 - a reading after the motion failed: say so
            self._end(False, "INTERNAL", f"reading the robot after {self.name}: {error}")
            return
        self._end(True)

    def cancel(self) -> None:
        with self._lock:
            self._cancel_requested = True
            handles = list(self._handles)
        for handle in handles:
            handle.cancel_goal_async()


class LoopExecution(_Outcome):
    """A loop the adapter runs on a thread of its own: `loop(execution)` returns (success, code,
    message) and watches `cancel_requested`."""

    def __init__(
        self,
        name: str,
        clock: Clock,
        duration_s: float,
        loop: Callable[[LoopExecution], tuple],
        on_end: Callable[[], None] | None = None,
    ) -> None:
        super().__init__(name, clock, duration_s, on_end)
        self.phase = "driving"
        self.cancel_requested = False
        self._thread = threading.Thread(target=self._run, args=(loop,), name=name, daemon=True)
        self._thread.start()

    def _run(self, loop: Callable[[LoopExecution], tuple]) -> None:
        try:
            self._end(*loop(self))
        except Exception as error:  # noqa: BLE001 - the loop lost the robot: a failed command
            self._end(False, "INTERNAL", f"{self.name}: {error}")

    def cancel(self) -> None:
        self.cancel_requested = True
