"""Pick a ROS 2 domain id that no other run on this machine is using.

Parallel test runs and demos must never see each other's nodes. A random id alone can collide,
so each candidate id is reserved with an exclusive lock on a file in the temp directory; the lock
lives as long as this process (the OS drops it when the process ends, even on a crash), and
child processes simply inherit ROS_DOMAIN_ID.
"""

from __future__ import annotations

import fcntl
import os
import random
import tempfile
from pathlib import Path
from typing import IO

# Domain ids 1..101 keep every participant's ports below the ephemeral range on Linux.
DOMAIN_IDS = range(1, 102)
_held_locks: dict[int, IO[bytes]] = {}


def reserve_domain_id(lock_dir: Path | None = None) -> int:
    """Reserve a free domain id for this process and return it; raise if all are taken."""
    directory = lock_dir or Path(tempfile.gettempdir()) / "sila-labware-ros-domains"
    directory.mkdir(parents=True, exist_ok=True)
    candidates = list(DOMAIN_IDS)
    random.SystemRandom().shuffle(candidates)
    for domain_id in candidates:
        if domain_id in _held_locks:
            continue
        lock_file = open(directory / f"{domain_id}.lock", "wb")  # noqa: SIM115 - held until exit
        try:
            fcntl.flock(lock_file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            lock_file.close()
            continue
        os.set_inheritable(lock_file.fileno(), False)
        _held_locks[domain_id] = lock_file
        return domain_id
    raise RuntimeError(
        f"every ROS domain id {DOMAIN_IDS.start}..{DOMAIN_IDS.stop - 1} is in use on this machine"
    )
