"""A robot-side node stops once the process that started it is gone.

Why: a deployment killed without its clean-up left its sim node and sequencer running in their ROS
domain; the next run that reserved that domain had two robots answer its goals ("more than one
action server", seen with a benchmark stopped by SIGTERM). Real processes: a parent that starts
the sequencer, then dies by SIGKILL (no clean-up of its own)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

WORLD = Path(__file__).resolve().parents[3] / "lab_description" / "worlds" / "default.yaml"
PARENT = (
    "import subprocess, sys, time\n"
    "child = subprocess.Popen([sys.executable, '-m', 'tiago_sim.sequencer', '--world', sys.argv[1]])\n"
    "print(child.pid, flush=True)\n"
    "time.sleep(600)\n"
)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    with open(f"/proc/{pid}/stat") as stat:  # a zombie has ended; only its exit status is left
        return stat.read().split(")")[-1].split()[0] != "Z"


# killed while the node still imports and loads (a busy machine stretches those seconds), or spinning
@pytest.mark.parametrize("parent_lives_s", [0.5, 3.0], ids=["while-loading", "spinning"])
def test_a_node_whose_parent_was_killed_shuts_down(parent_lives_s: float) -> None:
    parent = subprocess.Popen([sys.executable, "-c", PARENT, str(WORLD)], stdout=subprocess.PIPE, text=True)
    child = int(parent.stdout.readline())
    try:
        time.sleep(parent_lives_s)
        assert _alive(child)
        parent.send_signal(signal.SIGKILL)
        parent.wait(timeout=10)
        deadline = time.monotonic() + 60.0  # a busy machine: the node may finish loading first
        while _alive(child) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not _alive(child), "the orphaned sequencer kept running"
    finally:
        parent.kill()
        if _alive(child):
            os.kill(child, signal.SIGKILL)
