"""A robot-side file checked in a child process, before anything starts.

Why a child: the files a lab writes for the robot side (the world, the robot's limits) are read by
robot-side modules, which the SiLA side does not import (tests/test_architecture.py). Their own
check commands run as children and say every problem in their words, on stderr, exiting non-zero.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Sequence

CHECK_TIMEOUT_S = 60.0


def check_problems(module: str, arguments: Sequence[str]) -> list[str]:
    """Each problem `python -m module arguments...` reports, one line each (empty: it exited 0)."""
    done = subprocess.run(
        [sys.executable, "-m", module, *arguments],
        capture_output=True,
        text=True,
        timeout=CHECK_TIMEOUT_S,
        stdin=subprocess.DEVNULL,
        check=False,
    )
    if done.returncode == 0:
        return []
    return done.stderr.strip().splitlines() or [f"{module} exited with {done.returncode}"]
