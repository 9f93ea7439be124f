"""Start the small real ROS 2 peer (`ros_echo_server.py`) in its own process, for bridge tests."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

ECHO_SERVER = Path(__file__).with_name("ros_echo_server.py")


@contextmanager
def running_echo_peer(goal_seconds: float) -> Iterator[subprocess.Popen]:
    """The peer with goals that take `goal_seconds`; yields once it printed READY, stops it after."""
    process = subprocess.Popen(
        [sys.executable, str(ECHO_SERVER), "--goal-seconds", str(goal_seconds)],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert process.stdout is not None
        assert process.stdout.readline().strip() == "READY", "the echo peer did not start"
        yield process
    finally:
        process.terminate()
        process.wait(timeout=10)
