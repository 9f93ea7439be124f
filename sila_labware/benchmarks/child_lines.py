"""The lines a child process writes to a pipe, each waited for with a bound.

Why: `for line in process.stdout` and `readline()` block until the child writes or closes the
pipe; a child that hangs silently would hold a benchmark for ever. The lines are read on a daemon
thread into a queue, and `next_line` waits at most its timeout.

Threads: one daemon reader thread per stream; `next_line` on the caller's.
"""

from __future__ import annotations

import queue
import threading
from typing import IO


class ChildSilent(TimeoutError):
    """The child wrote no line within the time allowed."""


class ChildLines:
    """Lines of `stream` (a text pipe) as they come; None marks the end of the stream."""

    def __init__(self, stream: IO[str], name: str) -> None:
        self._name = name
        self._lines: queue.Queue[str | None] = queue.Queue()
        threading.Thread(target=self._read, args=(stream,), name=f"lines-of-{name}", daemon=True).start()

    def next_line(self, timeout_s: float) -> str | None:
        """The next line (without its newline), None once the stream has ended; ChildSilent if
        nothing came within `timeout_s`."""
        try:
            return self._lines.get(timeout=max(0.0, timeout_s))
        except queue.Empty:
            raise ChildSilent(f"{self._name} wrote nothing within {timeout_s:.1f} s") from None

    def _read(self, stream: IO[str]) -> None:
        try:
            for line in stream:
                self._lines.put(line.rstrip("\n"))
        except ValueError:  # the stream was closed under us: that is its end too
            pass
        self._lines.put(None)
