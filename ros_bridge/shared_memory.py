"""Remove the shared-memory segments that Fast DDS participants of dead processes left behind.

Why: every ROS 2 participant (each node's process) opens segments in /dev/shm for Fast DDS's
shared-memory transport, about 0.5 MB each, and removes them only when it shuts down cleanly. A
process that is killed (a campaign trial stopped at its timeout, a test's robot side after a crash,
Ctrl-C at the wrong instant) leaves them: three hours of campaigns and tests on one machine left
4,200 files and 0.96 GB. They are never reused, so they pile up until the machine restarts.

Which are dead: a participant holds an flock on each segment's `_el` file ("exclusive lock") for as
long as it lives; the kernel drops it when the process ends, however it ends. A segment whose lock
can be taken is therefore nobody's (Fast DDS's own `fastdds shm clean` decides the same way). A
segment younger than `min_age_s` is left alone: a participant creates the file an instant before it
locks it. Only a participant's own segments go (`fastrtps_` and 16 hex digits, a random name never
used again); the ports' segments (`fastrtps_port7000`) are shared, found again by their number by
the next participant, and bounded by the ports in use (14 MB in that same folder), so they stay.
Safe beside running deployments; any thread.
"""

from __future__ import annotations

import fcntl
import logging
import os
import re
import time
from pathlib import Path

log = logging.getLogger(__name__)

SHM_DIR = Path("/dev/shm")
PARTICIPANT_LOCK = re.compile(r"fastrtps_[0-9a-f]{16}_el")
MIN_AGE_S = 60.0


def _free(lock_file: Path) -> bool:
    """Whether no process holds the lock on `lock_file` (taken and released at once to find out)."""
    try:
        descriptor = os.open(lock_file, os.O_RDWR)
    except OSError:
        return False
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    else:
        fcntl.flock(descriptor, fcntl.LOCK_UN)
        return True
    finally:
        os.close(descriptor)


def remove_dead_segments(directory: Path = SHM_DIR, min_age_s: float = MIN_AGE_S) -> int:
    """Remove every Fast DDS participant segment in `directory` that no living process holds and that is
    older than `min_age_s`, with its lock file; returns how many files went."""
    if not directory.is_dir():
        return 0
    removed = 0
    oldest = time.time() - min_age_s
    for lock_file in directory.iterdir():
        if not PARTICIPANT_LOCK.fullmatch(lock_file.name):
            continue
        try:
            if lock_file.stat().st_mtime > oldest or not _free(lock_file):
                continue
        except OSError:  # gone meanwhile
            continue
        for path in (lock_file.with_name(lock_file.name.removesuffix("_el")), lock_file):
            try:
                path.unlink()
                removed += 1
            except FileNotFoundError:
                pass
            except OSError as error:
                log.debug("cannot remove %s: %s", path, error)
    if removed:
        log.info("removed %d shared-memory files of dead ROS processes from %s", removed, directory)
    return removed
