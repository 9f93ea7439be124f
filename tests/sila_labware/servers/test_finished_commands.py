"""Finished observable commands keep their results, not a thread each.

Before: sila2 waited out each finished command's lifetime (10 minutes) in a thread of its own, so
a busy serve process grew by 8 threads per transfer (1,098 threads after 131 transfers). Real
servers, a real sila2 client, the real robot side; the threads are this process's (the servers run
in it).
"""

from __future__ import annotations

import datetime
import threading
import time
from collections.abc import Iterator

import pytest
from sila2.framework import InvalidCommandExecutionUUID

from sila_labware.deployment.stack import Deployment
from tests.helpers.sila_stack import client_for, start_stack
from tests.helpers.transfer_steps import finish


@pytest.fixture(scope="module")
def stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Deployment]:
    deployment = start_stack(tmp_path_factory.mktemp("finished_commands"), insecure=True)
    yield deployment
    deployment.stop()


def test_many_finished_commands_leave_no_thread_behind(stack: Deployment) -> None:
    mobile = client_for(stack, stack.robot_server()).MobileRobotController
    finish(mobile.Dock())  # warm up: pools and subscriptions a first command starts
    before = threading.active_count()
    for _ in range(40):
        finish(mobile.Dock())  # docked already: each ends at once, its result kept
    assert threading.active_count() - before <= 4, "a thread per finished command is back"


def test_a_result_is_kept_for_the_lifetime_then_forgotten(stack: Deployment) -> None:
    served = stack.robot_server()
    mobile = client_for(stack, served).MobileRobotController
    instance = mobile.Dock()
    finish(instance)
    reaper = served.server.finished_commands
    reaper.sweep()  # the lifetime (10 minutes) has not passed: the result stays
    instance.get_responses()
    lifetime = reaper.lifetime
    try:
        reaper.lifetime = datetime.timedelta(0)
        assert reaper.sweep() >= 1
    finally:
        reaper.lifetime = lifetime
    with pytest.raises(InvalidCommandExecutionUUID):
        instance.get_responses()


@pytest.mark.soak
@pytest.mark.timeout(1500)
def test_threads_stay_flat_past_the_lifetime_while_results_expire(stack: Deployment) -> None:
    """A run longer than the lifetime: 2 finished commands a second for the lifetime plus 90 s.
    The kept results grow for the lifetime, then level off as the oldest are forgotten; the
    thread count stays flat throughout. Run apart: `./run test -m soak -s <this file>`."""
    served = stack.robot_server()
    mobile = client_for(stack, served).MobileRobotController
    reaper = served.server.finished_commands
    duration_s = reaper.lifetime.total_seconds() + 90.0

    def kept_results() -> int:
        return sum(
            len(managers)
            for servicer in served.server.feature_servicers.values()
            for managers in getattr(servicer, "observable_command_managers", {}).values()
        )

    finish(mobile.Dock())
    started = time.monotonic()
    samples: list[tuple[float, int, int]] = []
    next_sample = started
    while (elapsed := time.monotonic() - started) < duration_s:
        finish(mobile.Dock())
        if time.monotonic() >= next_sample:
            samples.append((round(elapsed), threading.active_count(), kept_results()))
            next_sample += 30.0
        time.sleep(0.5)
    samples.append((round(time.monotonic() - started), threading.active_count(), kept_results()))
    print("elapsed s, threads, kept results:", samples)
    threads = [count for _, count, _ in samples]
    assert max(threads) - min(threads) <= 4, samples
    at_lifetime = max(kept for elapsed, _, kept in samples if elapsed <= reaper.lifetime.total_seconds())
    assert samples[-1][2] <= at_lifetime + 10, "results older than the lifetime are not forgotten"
