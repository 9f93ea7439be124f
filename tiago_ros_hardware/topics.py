"""The robot's readings as they arrive on its topics, kept for the port's readings to answer from.

Why a history and a wait: a reading must show the robot as it stands when it is asked, not as it
stood before the last motion ended (the topics arrive at their own rates, and a simulator runs
faster than real time). Each topic keeps its latest messages with their stamps and counts them as
they arrive; `after` waits for one that arrived after a given count (the adapter notes the count when
a command ends, and skips one more: a message in flight then may show the robot from before),
`newer_than` for one stamped after a given robot time, and `at` finds the one nearest a stamp (a
camera frame's joints).

Threads: callbacks on the node's executor threads; readers on any thread (a lock and a condition).
"""

from __future__ import annotations

import bisect
import threading
from collections import deque
from typing import Any

from robot_port.hardware import HardwareUnavailable

HISTORY = 400
"""Messages kept per topic (20 s of /joint_states at 20 Hz)."""


def stamp_seconds(message: Any) -> float:
    """A message's header stamp in seconds (robot time)."""
    stamp = message.header.stamp
    return stamp.sec + stamp.nanosec * 1e-9


class TopicHistory:
    """The last HISTORY messages of one topic, by stamp, and a wait for a newer one."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._stamps: deque[float] = deque(maxlen=HISTORY)
        self._messages: deque[Any] = deque(maxlen=HISTORY)
        self._changed = threading.Condition()
        self.count = 0  # messages received so far

    def add(self, message: Any, stamp_s: float | None = None) -> None:
        stamp = stamp_seconds(message) if stamp_s is None else stamp_s
        with self._changed:
            if self._stamps and stamp < self._stamps[-1]:  # out of order: a time reset
                self._stamps.clear()
                self._messages.clear()
            self._stamps.append(stamp)
            self._messages.append(message)
            self.count += 1
            self._changed.notify_all()

    def latest(self) -> tuple[float, Any] | None:
        with self._changed:
            return (self._stamps[-1], self._messages[-1]) if self._stamps else None

    def after(self, count: int, timeout_s: float) -> tuple[float, Any]:
        """The latest message, once more than `count` messages have arrived (waiting up to `timeout_s`
        of wall time)."""
        with self._changed:
            if not self._changed.wait_for(lambda: self.count > count and bool(self._stamps), timeout_s):
                raise HardwareUnavailable(f"no {self.name} from the robot within {timeout_s:g} s")
            return self._stamps[-1], self._messages[-1]

    def newer_than(self, after_s: float, timeout_s: float) -> tuple[float, Any]:
        """The first message stamped after `after_s` (waiting for it up to `timeout_s` of wall time)."""
        with self._changed:
            if not self._changed.wait_for(
                lambda: bool(self._stamps) and self._stamps[-1] > after_s, timeout_s
            ):
                raise HardwareUnavailable(
                    f"no {self.name} after robot time {after_s:.3f} s within {timeout_s:g} s"
                )
            index = bisect.bisect_right(list(self._stamps), after_s)
            return self._stamps[index], self._messages[index]

    def at(self, stamp_s: float) -> Any:
        """The message nearest `stamp_s` (None if there is none yet)."""
        with self._changed:
            if not self._stamps:
                return None
            stamps = list(self._stamps)
            index = bisect.bisect_left(stamps, stamp_s)
            nearby = [i for i in (index - 1, index) if 0 <= i < len(stamps)]
            return self._messages[min(nearby, key=lambda i: abs(stamps[i] - stamp_s))]
