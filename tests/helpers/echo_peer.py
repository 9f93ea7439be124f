"""Start the small real ROS 2 peer (`ros_echo_server.py`) in its own process, for bridge tests."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

ECHO_SERVER = Path(__file__).with_name("ros_echo_server.py")


@contextmanager
def running_echo_peer(
    goal_seconds: float, accept_delay_s: float = 0.0, goal_log: Path | None = None
) -> Iterator[subprocess.Popen]:
    """The peer with goals that take `goal_seconds`, answering goal requests after `accept_delay_s`
    and logging goal events to `goal_log` (see ros_echo_server.py); yields once it printed READY,
    stops it after."""
    arguments = ["--goal-seconds", str(goal_seconds), "--accept-delay-s", str(accept_delay_s)]
    if goal_log is not None:
        arguments += ["--goal-log", str(goal_log)]
    process = subprocess.Popen(
        [sys.executable, str(ECHO_SERVER), *arguments], stdout=subprocess.PIPE, text=True
    )
    try:
        assert process.stdout is not None
        assert process.stdout.readline().strip() == "READY", "the echo peer did not start"
        yield process
    finally:
        process.terminate()
        process.wait(timeout=10)


def goal_events(goal_log: Path) -> list[str]:
    """The events the peer logged so far ("accepted POI", "canceled POI", ...)."""
    return goal_log.read_text().splitlines() if goal_log.exists() else []
