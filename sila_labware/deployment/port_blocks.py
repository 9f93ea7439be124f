"""Reserve a block of SiLA ports that no other run on this machine is using.

Why: `bench --jobs` numbers its workers and gives worker k the ports from `--port-base` + 10 k; on a
Ray cluster no one numbers the trials of one host (two Ray nodes may share a host, each with its
own workers); and tests pick free ports while a campaign may run beside them. So a trial's process
(and a test's block, `claim_free_block`) reserves its block as ros_bridge.domain reserves a ROS domain:
an exclusive lock on a file per block in the temp directory, held as long as the process lives
(the OS drops it when the process ends, even on a crash), and only on a block whose ports are
free right now (a server outside this scheme may hold some).
"""

from __future__ import annotations

import fcntl
import os
import tempfile
from pathlib import Path
from typing import IO

from sila_labware.servers.serving import port_is_free

_held: dict[int, list[IO[bytes]]] = {}  # first port of the block this process holds -> its locks
_claimed: list[IO[bytes]] = []  # locks of the blocks `claim_free_block` handed out (tests' servers)


def _lock_directory(lock_dir: Path | None) -> Path:
    directory = lock_dir or Path(tempfile.gettempdir()) / "sila-labware-ports"
    directory.mkdir(parents=True, exist_ok=True)
    return directory


def reserve_port_block(first: int, size: int, host: str = "127.0.0.1", lock_dir: Path | None = None) -> int:
    """The first port of a block of `size` ports, from `first` on in steps of `size`, reserved for this
    process on this machine; the same block again when this process holds one already. Raises
    RuntimeError when every block up to port 65535 is taken."""
    if _held:
        return next(iter(_held))
    directory = _lock_directory(lock_dir)
    for base in range(first, 65536 - size + 1, size):
        locks = _locked_if_free(directory, range(base, base + size), host)
        if locks is not None:
            _held[base] = locks
            return base
    raise RuntimeError(f"every block of {size} SiLA ports from {first} on is in use on this machine")


def claim_free_block(ports: range, host: str = "127.0.0.1", lock_dir: Path | None = None) -> bool:
    """Lock `ports` for this process (until it ends) if no other run holds any of them and all are
    free now: a test's servers then never take the block a campaign's trial reserved between two
    of its trials (seen: tests beside a campaign on the ports 54000 and up failed, passing alone)."""
    locks = _locked_if_free(_lock_directory(lock_dir), ports, host)
    if locks is None:
        return False
    _claimed.extend(locks)
    return True


def _locked_if_free(directory: Path, ports: range, host: str) -> list[IO[bytes]] | None:
    locks = _lock_ports(directory, ports)
    if locks is not None and not all(port_is_free(host, port) for port in ports):
        _release(locks)  # another run's servers may free these ports later
        return None
    return locks


def _lock_ports(directory: Path, ports: range) -> list[IO[bytes]] | None:
    """A lock per port (blocks of other sizes or bases overlap), all or none."""
    locks: list[IO[bytes]] = []
    for port in ports:
        lock_file = open(directory / f"{port}.lock", "wb")  # noqa: SIM115 - held until exit
        try:
            fcntl.flock(lock_file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            lock_file.close()
            _release(locks)
            return None
        os.set_inheritable(lock_file.fileno(), False)
        locks.append(lock_file)
    return locks


def _release(locks: list[IO[bytes]]) -> None:
    for lock_file in locks:
        lock_file.close()  # closing the file drops its lock
