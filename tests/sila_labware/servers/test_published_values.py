"""A value published through `PublishedValues` is what the next subscription receives first.

sila2's own subscription manager thread reads the queue; its converter is slowed to 50 ms, as a
manager thread starved on a loaded machine is, which makes the race that `wait` closes certain.
"""

from __future__ import annotations

import time
from types import SimpleNamespace

from sila2.server.observables.subscription_manager_thread import SubscriptionManagerThread

from sila_labware.servers.published_values import PublishedValues

PROPERTY = "org.silastandard/examples/Example/v1/Property/State"


def slow_converter(value: str) -> str:
    time.sleep(0.05)
    return value


class Context:
    """The one call sila2's manager makes on a gRPC servicer context."""

    def add_callback(self, callback: object) -> bool:
        return True


def first_value_of_a_new_subscription(manager: SubscriptionManagerThread) -> str:
    return next(manager.add_subscription(Context()))


def test_a_subscription_after_wait_receives_the_value_just_published() -> None:
    implementation = SimpleNamespace()
    published = PublishedValues(implementation, "State")
    queue = implementation._State_producer_queue
    queue.put("Docked")
    published.wait()  # no reader yet: returns at once
    manager = SubscriptionManagerThread(PROPERTY, queue, slow_converter)
    manager.start()
    try:
        published.wait()
        assert first_value_of_a_new_subscription(manager) == "Docked"
        queue.put("Navigating")
        published.wait()  # without it, the subscription gets "Docked": the manager is still converting
        assert first_value_of_a_new_subscription(manager) == "Navigating"
        for state in ("Idle", "Manipulating", "Idle"):
            queue.put(state)
        published.wait()
        assert first_value_of_a_new_subscription(manager) == "Idle"
    finally:
        manager.cancel_producer()
        manager.join(timeout=5)
