"""A campaign worker that cannot stop its deployment is ended by the kernel, and its trial runs again.

Why the kernel: Fast DDS can spin for minutes destroying a participant, inside rclpy while it holds
the GIL (the bridge's node, seen in a 200-trial campaign: the worker hung for good), and then no
Python code in the process runs again, a watchdog thread included. An alarm whose disposition is
SIGALRM's default ends the process without any of it; the campaign then counts a lost worker and
runs its trials again (workers.py, ray_campaign.py). Any thread may call; only the main thread arms
the alarm.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable

STOP_DEADLINE_S = 60
"""A deployment stops in seconds (2 s per process at most before SIGKILL); one that takes longer hangs."""


def stop_within(stop: Callable[[], None], deadline_s: int | None) -> None:
    """`stop()`, and with `deadline_s` the kernel ends this process if it takes longer (SIGALRM's
    default action: no Python code has to run for it)."""
    if deadline_s is None or threading.current_thread() is not threading.main_thread():
        stop()  # an alarm's disposition is set from the main thread only
        return
    before = signal.signal(signal.SIGALRM, signal.SIG_DFL)
    signal.alarm(deadline_s)
    try:
        stop()
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, before)
