"""The lock state behind LockController (`ServerLock`), on a clock the test turns: no server, no gRPC.

The whole-stack behaviour (two clients, refusals at initiation) is in test_sila_core_features.py.
"""

from __future__ import annotations

import pytest
from sila2.features.lockcontroller import InvalidLockIdentifier, ServerAlreadyLocked, ServerNotLocked

from sila_labware.servers.locking import ServerLock


class Clock:
    def __init__(self) -> None:
        self.now_s = 100.0

    def __call__(self) -> float:
        return self.now_s


def test_an_unlocked_server_admits_any_token_or_none_needed() -> None:
    lock = ServerLock(Clock())
    assert not lock.locked
    lock.admit("anything")  # no error: a token sent to an unlocked server is ignored
    with pytest.raises(ServerNotLocked):
        lock.unlock("anything")


def test_a_locked_server_admits_only_its_token_and_only_its_holder_unlocks() -> None:
    lock = ServerLock(Clock())
    lock.lock("holder", 60.0)
    assert lock.locked
    lock.admit("holder")
    with pytest.raises(InvalidLockIdentifier):
        lock.admit("intruder")
    with pytest.raises(ServerAlreadyLocked):
        lock.lock("holder", 60.0)  # not even its holder locks twice
    with pytest.raises(InvalidLockIdentifier):
        lock.unlock("intruder")
    lock.unlock("holder")
    assert not lock.locked


def test_the_lock_lapses_after_its_timeout_of_inactivity_and_each_admitted_call_restarts_it() -> None:
    clock = Clock()
    lock = ServerLock(clock)
    lock.lock("holder", 10.0)
    for _ in range(5):  # 5 x 8 s = 40 s, each with a call: still locked
        clock.now_s += 8.0
        lock.admit("holder")
    clock.now_s += 8.0
    with pytest.raises(InvalidLockIdentifier):
        lock.admit("intruder")  # a refused call does not restart the timeout
    clock.now_s += 2.0
    assert lock.locked  # 10 s exactly since the last admitted call
    clock.now_s += 0.01
    assert not lock.locked
    lock.admit("intruder")  # the server is free
    lock.lock("intruder", 10.0)


def test_a_timeout_of_zero_never_lapses() -> None:
    clock = Clock()
    lock = ServerLock(clock)
    lock.lock("holder", 0.0)
    clock.now_s += 1e6
    assert lock.locked
