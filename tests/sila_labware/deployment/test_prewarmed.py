"""Children forked from the prewarmed fork server behave as spawned ones: arguments, environment,
output, exit code, own session, and a parent that can wait for them and stop them.

Real parts: the fork server process (prewarmed.py) and real forked children running a module.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import time
from pathlib import Path

from sila_labware.deployment.prewarmed import MESSAGE_BYTES, ORPHANED, ForkedChild, _ForkServer
from sila_labware.deployment.processes import ProcessGroup

PROBE = "tests.helpers.child_probe"


def test_a_forked_module_gets_its_arguments_environment_output_and_exit_code(tmp_path: Path) -> None:
    group = ProcessGroup({"PROBE_VALUE": "seen", "PATH": os.environ["PATH"]}, tmp_path, prewarmed=True)
    child = group.start_python_module("probe", PROBE, ["report", "3"])
    assert isinstance(child.popen, ForkedChild)
    assert child.popen.wait(30.0) == 3
    report = json.loads((tmp_path / "probe.log").read_text().splitlines()[-1])
    assert report["argv"] == ["report", "3"]
    assert report["probe_value"] == "seen"
    assert report["pid"] == child.popen.pid
    assert report["pgid"] == report["pid"], "the child leads its own process group"
    assert report["parent"] == os.getpid(), "the asking process is the child's parent"
    assert report["name"] == "child_probe", "ps names a forked child after its module"
    group.stop()


def test_stopping_the_group_ends_forked_children_by_signal_even_right_after_the_start(
    tmp_path: Path,
) -> None:
    group = ProcessGroup(dict(os.environ), tmp_path, prewarmed=True)
    running = group.start_python_module("running", PROBE, ["sleep"])
    deadline = time.monotonic() + 30.0
    while "SLEEPING" not in (tmp_path / "running.log").read_text():
        assert time.monotonic() < deadline, "the forked child wrote nothing to its log"
        time.sleep(0.05)
    group.check_running()
    just_started = group.start_python_module("just_started", PROBE, ["sleep"])
    group.stop(timeout_s=10.0)
    assert running.popen.returncode == -signal.SIGTERM
    assert just_started.popen.returncode == -signal.SIGTERM, "SIGTERM must reach a child in its first moments"


def test_a_child_that_is_not_up_shows_where_it_waits(tmp_path: Path) -> None:
    """What a deployment logs when its robot side does not come up in time: each child's stacks."""
    group = ProcessGroup(dict(os.environ), tmp_path, prewarmed=True)
    group.start_python_module("waiting", PROBE, ["sleep"])
    deadline = time.monotonic() + 30.0
    while "SLEEPING" not in (tmp_path / "waiting.log").read_text():
        assert time.monotonic() < deadline, "the forked child wrote nothing to its log"
        time.sleep(0.05)
    stacks = group.stacks(wait_s=2.0)
    group.stop()
    assert stacks.startswith("--- waiting (pid ")
    assert 'child_probe.py", line' in stacks and "in main" in stacks, stacks


def test_children_forked_one_after_the_other_are_independent(tmp_path: Path) -> None:
    group = ProcessGroup(dict(os.environ), tmp_path, prewarmed=True)
    first = group.start_python_module("first", PROBE, ["report", "0"])
    second = group.start_python_module("second", PROBE, ["report", "5"])
    assert first.popen.wait(30.0) == 0
    assert second.popen.wait(30.0) == 5
    assert first.popen.pid != second.popen.pid
    group.stop()


def test_a_child_whose_asker_is_gone_ends_before_it_starts(tmp_path: Path) -> None:
    """The asking process ended while its child was being re-parented to it (a Ray worker lost
    mid-start): the child then finds another parent than the asker. Here the request names another
    asker (init) than the process the child comes to; the child must not run its module."""
    server = _ForkServer()
    connection = server._connection()
    request = {"module": PROBE, "arguments": ["report", "0"], "environment": dict(os.environ), "asker": 1}
    log = tmp_path / "orphan.log"
    with log.open("w") as output:
        socket.send_fds(connection, [json.dumps(request).encode()], [output.fileno()])
    child = ForkedChild(int(json.loads(connection.recv(MESSAGE_BYTES))["pid"]), [PROBE])
    try:
        assert child.wait(30.0) == 1
    finally:
        connection.close()
        server._process.wait(30.0)
    written = log.read_text()
    assert ORPHANED in written and "pid 1 (the parent is pid " in written, written
    assert '"argv"' not in written, "the module ran"
