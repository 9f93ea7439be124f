"""Mirror a ROS topic: keep its latest message and tell listeners when it changes.

Threads: the subscription callback runs on the ROS thread of a `RosRuntime`; it stores the
message under a lock and calls the change listeners there (keep them short: they typically
push a value into a SiLA observable property). Readers on any thread use `latest` or
`wait_for_message`.

Observable SiLA properties only want changes, while our publishers also repeat the same state
at 2 Hz; `key` decides what counts as a change (default: the whole message without its stamp).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any, Generic, TypeVar

from rclpy.qos import QoSDurabilityPolicy, QoSHistoryPolicy, QoSProfile, QoSReliabilityPolicy

from ros_bridge.errors import BridgeTimeout
from ros_bridge.runtime import RosRuntime

logger = logging.getLogger(__name__)

M = TypeVar("M")

STATE_QOS = QoSProfile(
    history=QoSHistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=QoSReliabilityPolicy.RELIABLE,
    durability=QoSDurabilityPolicy.VOLATILE,
)

INVENTORY_QOS = QoSProfile(
    history=QoSHistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=QoSReliabilityPolicy.RELIABLE,
    durability=QoSDurabilityPolicy.TRANSIENT_LOCAL,
)
"""/labware_inventory: published on change (and at 1 Hz), so a late reader gets the last one at once."""


def message_without_stamp(message: Any) -> tuple:
    """A comparable snapshot of a message, ignoring a top-level `stamp` field."""
    return tuple(
        repr(getattr(message, field)) for field in message.get_fields_and_field_types() if field != "stamp"
    )


class TopicMirror(Generic[M]):
    """The latest message of one topic, with change listeners."""

    def __init__(
        self,
        runtime: RosRuntime,
        message_type: type[M],
        topic: str,
        qos: QoSProfile = STATE_QOS,
        key: Callable[[M], Any] = message_without_stamp,
        listeners: Sequence[Callable[[M], None]] = (),
    ) -> None:
        """Subscribe to `topic`; `listeners` hear from the first message on (one added later with
        `add_listener` may miss a message that came before it)."""
        self.topic = topic
        self._runtime = runtime
        self._key = key
        self._condition = threading.Condition()
        self._latest: M | None = None
        self._latest_key: Any = None
        self._received_count = 0
        self._listeners: list[Callable[[M], None]] = list(listeners)
        self._subscription = runtime.call(
            lambda: runtime.node.create_subscription(message_type, topic, self._on_message, qos)
        )

    @property
    def latest(self) -> M | None:
        """The last message received, or None before the first."""
        with self._condition:
            return self._latest

    @property
    def received_count(self) -> int:
        with self._condition:
            return self._received_count

    def add_listener(self, listener: Callable[[M], None]) -> None:
        """Call `listener(message)` on every change (on the ROS thread)."""
        with self._condition:
            self._listeners.append(listener)

    def wait_for_message(self, timeout_s: float = 10.0, predicate: Callable[[M], bool] | None = None) -> M:
        """Wait until a message (matching `predicate`, if given) is there, and return it."""
        deadline = time.monotonic() + timeout_s
        with self._condition:
            while self._latest is None or (predicate is not None and not predicate(self._latest)):
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    what = "no message" if self._latest is None else "no matching message"
                    raise BridgeTimeout(f"{what} on {self.topic} within {timeout_s:.1f} s")
                self._condition.wait(remaining)
            return self._latest

    def destroy(self) -> None:
        if self._runtime.running:
            self._runtime.call(lambda: self._runtime.node.destroy_subscription(self._subscription))

    def inject(self, message: M) -> None:
        """Take `message` as if it had been received (local knowledge, such as "the robot side is
        gone"); the next real message replaces it. Listeners run on the calling thread: call this on
        the ROS thread while the runtime runs."""
        self._on_message(message)

    def _on_message(self, message: M) -> None:
        """Listeners first, then waiters: whoever returns from `wait_for_message` with this message
        finds everything fed by the listeners (SiLA properties) already updated. Only the ROS
        thread calls this, so messages cannot overtake each other between the two steps."""
        message_key = self._key(message)
        with self._condition:
            changed = self._latest is None or message_key != self._latest_key
            listeners = list(self._listeners) if changed else []
        for listener in listeners:
            try:
                listener(message)
            except Exception:  # noqa: BLE001 - a broken listener must not stop the executor
                logger.exception("listener of %s failed", self.topic)
        with self._condition:
            self._latest, self._latest_key = message, message_key
            self._received_count += 1
            self._condition.notify_all()
