"""SiLA port blocks reserved host-wide: two processes never get the same ports, a port in use is
skipped, and a block is free again once its process ends.

Why processes: on a Ray cluster no one numbers the trials of one host, so each trial's process
reserves its own block (port_blocks.py); the lock is per process, as the test runs it.
"""

from __future__ import annotations

import socket
import subprocess
import sys
import tempfile
from pathlib import Path

from sila_labware.testing.ports import free_port_base

SIZE = 10
RESERVE = (
    "import sys; from pathlib import Path; "
    "from sila_labware.deployment.port_blocks import reserve_port_block; "
    "print(reserve_port_block(int(sys.argv[1]), int(sys.argv[2]), lock_dir=Path(sys.argv[3])), flush=True); "
    "sys.stdin.read()"  # holds the block until the test closes its stdin
)


def holder(first: int, lock_dir: Path) -> tuple[subprocess.Popen[str], int]:
    """A process holding a block from `first` on, and the block's first port."""
    process = subprocess.Popen(
        [sys.executable, "-c", RESERVE, str(first), str(SIZE), str(lock_dir)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert process.stdout is not None
    return process, int(process.stdout.readline())


def release(process: subprocess.Popen[str]) -> None:
    assert process.stdin is not None
    process.stdin.close()
    process.wait(timeout=30)


def test_two_processes_get_blocks_of_their_own_and_a_busy_port_is_skipped(tmp_path: Path) -> None:
    first = free_port_base(4 * SIZE)
    with socket.socket() as busy:  # a server outside the scheme on the first block's last port
        busy.bind(("127.0.0.1", first + SIZE - 1))
        busy.listen()
        one, one_base = holder(first, tmp_path)
        two, two_base = holder(first, tmp_path)
    try:
        assert one_base == first + SIZE  # the first block has a port in use
        assert two_base == first + 2 * SIZE  # the second is held by the other process
    finally:
        release(one)
    three, three_base = holder(first, tmp_path)
    try:
        assert three_base in (first, first + SIZE)  # a block comes free with its process
    finally:
        release(two)
        release(three)


def test_a_test_never_picks_the_ports_a_campaign_trial_holds() -> None:
    """Tests pick free ports while a campaign may run beside them: a block a trial reserved (free
    between two of its trials, or before its servers bind) is not free for a test."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        near = probe.getsockname()[1]
    first = min(near, 65536 - 3 * SIZE)
    trial, held = holder(first, Path(tempfile.gettempdir()) / "sila-labware-ports")
    try:
        picked = free_port_base(SIZE, candidates=range(held, held + 3 * SIZE, SIZE))
        assert picked != held and picked in (held + SIZE, held + 2 * SIZE)
    finally:
        release(trial)
