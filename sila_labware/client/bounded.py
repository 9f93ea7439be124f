"""A bound for every blocking call into sila2's client: it sets no gRPC deadline, so a server that
accepts the connection but never answers would hold the caller for ever.

`bounded(call, timeout_s, command)` runs `call` on a thread of its own and waits for it at most
`timeout_s`; then it raises ServerUnreachable naming the command. Waiting this way also keeps the
caller interruptible: Ctrl-C raises KeyboardInterrupt in the caller's wait, where sila2 would
have caught it inside the call and reported it as a connection error.

Threads: the caller's waits; the call runs on a daemon thread, which a call given up keeps until
gRPC returns (its result is dropped).
"""

from __future__ import annotations

import concurrent.futures
import threading
from collections.abc import Callable
from typing import TypeVar

from sila_labware.client.errors import ServerUnreachable

T = TypeVar("T")

CALL_TIMEOUT_S = 30.0
"""For one unary call (a property read, an unobservable command, starting an observable one,
fetching its responses, connecting): our servers answer these in milliseconds; the bound is for
a server that hangs."""


def bounded(call: Callable[[], T], timeout_s: float, command: str) -> T:
    """`call()`'s value or exception, or ServerUnreachable if it takes longer than `timeout_s`."""
    answer: concurrent.futures.Future[T] = concurrent.futures.Future()

    def run() -> None:
        try:
            answer.set_result(call())
        except BaseException as error:  # noqa: BLE001 - handed to the waiting caller
            answer.set_exception(error)

    threading.Thread(target=run, name=f"sila-call {command}", daemon=True).start()
    try:
        return answer.result(timeout=timeout_s)
    except concurrent.futures.TimeoutError:
        raise ServerUnreachable(f"no answer within {timeout_s:.0f} s", command=command) from None
