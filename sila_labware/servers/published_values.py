"""Observable property values that a client reads back once their update has returned.

Why: sila2's generated `update_X(value)` only puts the value on a producer queue; a thread of
sila2's (`SubscriptionManagerThread`) takes it off and only then hands it to new subscriptions, and
a client's `get` is a new subscription. A command that answers right after the robot's state
changed could thus be followed by a `get` that still reads the old state (seen under load:
RobotState "Navigating" read after StopMotion had answered). `PublishedValues` puts a counting
queue in place of each producer queue and lets the publisher wait, bounded, until sila2's thread
has taken every value and come back for the next, which it does only after it has stored the
value it hands to new subscriptions.

Threads: `wait` runs on the publisher's thread (the ROS thread for the robot's status), sila2's
manager threads call `get`; the wait is microseconds on an idle machine and bounded under load.
"""

from __future__ import annotations

import logging
import threading
import time
from queue import Queue
from typing import Any

logger = logging.getLogger(__name__)

# Long enough for a starved manager thread on a loaded machine, short enough that the ROS thread
# (which also delivers goal results) is never held up noticeably.
WAIT_S = 0.5


class HandedQueue(Queue):
    """A producer queue that counts what was put on it and how often its reader came back."""

    def __init__(self) -> None:
        super().__init__()
        self._counts = threading.Condition()
        self._puts = 0
        self._gets = 0

    def put(self, item: Any, block: bool = True, timeout: float | None = None) -> None:
        with self._counts:  # counted before it is there: a reader can never be ahead of the count
            self._puts += 1
        super().put(item, block, timeout)

    def get(self, block: bool = True, timeout: float | None = None) -> Any:
        with self._counts:
            self._gets += 1
            self._counts.notify_all()
        return super().get(block, timeout)

    def wait_taken(self, timeout_s: float) -> bool:
        """True once the reader took every value put so far and asked for the next, or when no
        reader has started yet (sila2's thread then takes the newest value before any client can
        subscribe)."""
        with self._counts:
            return self._counts.wait_for(lambda: self._gets == 0 or self._gets > self._puts, timeout_s)


class PublishedValues:
    """The producer queues of a feature implementation's observable properties, made countable.

    Made in the implementation's constructor, before sila2 starts its manager threads (when the
    implementation is set on the server; they take the producer queues as they find them then)."""

    def __init__(self, implementation: object, *properties: str) -> None:
        self._queues: dict[str, HandedQueue] = {}
        for name in properties:
            queue = HandedQueue()
            setattr(implementation, f"_{name}_producer_queue", queue)
            self._queues[name] = queue

    def wait(self) -> None:
        """Return once every value published so far is what a new subscription receives, or after
        WAIT_S in all."""
        deadline = time.monotonic() + WAIT_S
        for name, queue in self._queues.items():
            if not queue.wait_taken(max(deadline - time.monotonic(), 0.0)):
                logger.warning("sila2 took longer than %.1f s to take up a new value of %s", WAIT_S, name)
                return
