"""Fast DDS's shared-memory files of a killed ROS process are removed; a living process keeps its own.

Why: a killed participant leaves about 0.5 MB in /dev/shm for ever; a campaign kills robot sides at
their timeouts and tests kill what hangs, so a busy machine filled 0.96 GB in three hours. Real
rclpy processes here: one killed with SIGKILL, one alive; their files aged on purpose so that the
cleaner, which leaves young files alone (another test's participant may be starting), judges them.
Other tests' deployments run the same cleaner meanwhile; that is what the living process's files
must survive.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from ros_bridge.shared_memory import PARTICIPANT_LOCK, SHM_DIR, remove_dead_segments

NODE = (
    "import rclpy, time; rclpy.init(); node = rclpy.create_node('shm_probe'); "
    "print('up', flush=True); time.sleep(120)"
)


def _own_locks(pid: int) -> set[str]:
    """The participant lock files process `pid` holds open (it keeps each open for its flock). Read from
    the process itself: other tests' participants create theirs in the same folder at the same time."""
    names = set()
    for descriptor in Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = Path(os.readlink(descriptor))
        except OSError:  # closed meanwhile
            continue
        if target.parent == SHM_DIR and PARTICIPANT_LOCK.fullmatch(target.name):
            names.add(target.name)
    return names


def _start_node() -> tuple[subprocess.Popen, set[str]]:
    """A process with one ROS node, and the participant lock files it holds."""
    process = subprocess.Popen([sys.executable, "-c", NODE], stdout=subprocess.PIPE, text=True)
    assert process.stdout is not None and process.stdout.readline().strip() == "up"
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline:
        if own := _own_locks(process.pid):
            return process, own
        time.sleep(0.1)
    raise AssertionError("the node opened no shared-memory segment")


def _age(names: set[str]) -> None:
    """Date the files two minutes back, past the cleaner's minimum age."""
    then = time.time() - 120.0
    for name in names:
        for path in (SHM_DIR / name, SHM_DIR / name.removesuffix("_el")):
            os.utime(path, (then, then))


def test_a_killed_process_segments_go_and_a_living_ones_stay() -> None:
    killed, killed_locks = _start_node()
    alive, alive_locks = _start_node()
    try:
        killed.send_signal(signal.SIGKILL)
        killed.wait(timeout=10)
        _age(killed_locks | alive_locks)
        assert all((SHM_DIR / name).exists() for name in killed_locks)  # left behind by the kill
        # another test's deployment may clean at the same moment (every start does): the files must be
        # gone, whoever removed them. A cleaner that finds a lock taken by another cleaner's probe
        # leaves the file to that one, which unlinks it an instant later (seen once in a loaded CI run).
        remove_dead_segments()
        killed_files = [SHM_DIR / name for name in killed_locks]
        killed_files += [SHM_DIR / name.removesuffix("_el") for name in killed_locks]
        deadline = time.monotonic() + 5.0
        while any(path.exists() for path in killed_files) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(path.exists() for path in killed_files)
        for name in alive_locks:
            assert (SHM_DIR / name).exists() and (SHM_DIR / name.removesuffix("_el")).exists()
        assert alive.poll() is None
    finally:
        for process in (killed, alive):
            process.kill()
            process.wait(timeout=10)


def test_young_files_are_left_alone(tmp_path: Path) -> None:
    lock = tmp_path / "fastrtps_0123456789abcdef_el"
    segment = tmp_path / "fastrtps_0123456789abcdef"
    lock.touch()
    segment.write_bytes(b"\0" * 16)
    port = tmp_path / "fastrtps_port7000_el"
    port.touch()
    assert remove_dead_segments(tmp_path) == 0  # nobody holds it, but it may be a participant starting
    assert remove_dead_segments(tmp_path, min_age_s=0.0) == 2
    assert not lock.exists() and not segment.exists()
    assert port.exists()  # ports are shared and found again by number: never removed
