"""Cancelling one robot command: a token per command execution, read by the robot between its goals.

Why a token, not just "cancel the running goal": a command such as PrepareForInput sends several
ROS goals one after the other (undock, then drive), and a cancel may land before the first goal,
between two goals, or while one runs. Cancelling only the running goal would miss the first two
cases and let the command drive on. With a token the robot checks before it sends each goal and
right after it registered one, so every case ends the command.

Theory of operation:
- Whoever offers cancelling (the SiLA layer) creates one `CancelToken` per command execution and
  runs that command inside `cancellable(token)`. The token is bound to the command's own thread
  (a context variable), so two commands on two handler threads never see each other's token.
- To cancel, call `RobotController.cancel_command(token, reason)`: it marks the token (for good;
  a token is never reset) and cancels that command's running goal, if any.
- `RobotController` reads `current_token()` on the command's thread; a cancelled token turns the
  next goal into a CANCELED outcome without sending it. The command then ends with its own defined
  error (LabwareNotPicked/LabwareNotPlaced, MotionStopped, ...), its message naming the reason.
- A cancel that lands after the command's last goal ended changes nothing: the motion is done and
  the command reports what happened.

Threads: `cancel` runs on the canceller's thread, `cancelled`/`reason` are read on the command's
thread; an Event and a lock make that safe. This module imports neither SiLA nor ROS.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar


class CancelToken:
    """The cancel request of one command execution: set at most once, never cleared."""

    def __init__(self) -> None:
        self._cancelled = threading.Event()
        self._lock = threading.Lock()
        self._reason = ""

    def cancel(self, reason: str) -> None:
        """Mark the command as cancelled; the first reason given is kept."""
        with self._lock:
            if not self._cancelled.is_set():
                self._reason = reason
                self._cancelled.set()

    @property
    def cancelled(self) -> bool:
        return self._cancelled.is_set()

    @property
    def reason(self) -> str:
        """Why the command was cancelled ("" while it is not)."""
        with self._lock:
            return self._reason


_current_token: ContextVar[CancelToken | None] = ContextVar("robot_command_cancel_token", default=None)


@contextmanager
def cancellable(token: CancelToken) -> Iterator[CancelToken]:
    """Run the robot command of this thread under `token` (see the module docstring)."""
    previous = _current_token.set(token)
    try:
        yield token
    finally:
        _current_token.reset(previous)


def current_token() -> CancelToken | None:
    """The token of the command running on this thread, None outside `cancellable`."""
    return _current_token.get()
