"""Soak: many standard transfers back and forth in ONE `sila-labware serve` process.

Why a subprocess and not `start_stack`: the question is whether the program a lab runs overnight
leaks memory, threads, goals or subscriptions, so the test watches that program's processes from
outside (/proc) and talks to it only as a scheduler would (SiLA over gRPC).

Run apart from the quick suite: `pytest -m soak tests/sila_labware/deployment/test_soak.py -s`
(the figures are printed and, with SOAK_REPORT=path, written as JSON). SOAK_TRANSFERS changes the
count (default 50); SOAK_PORT_BASE fixes the servers' first port (default: a free block). After
every transfer the localised pose and raw odometry are compared with the simulator's truth
(tests/helpers/pose_errors); the report gives their median, maximum and last values.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import pytest
from action_msgs.msg import GoalStatus, GoalStatusArray
from rclpy.action import get_action_names_and_types
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sila2.client import SilaClient

from ros_bridge.runtime import RosRuntime
from tests.helpers.pose_errors import PoseErrorProbe
from tests.helpers.sila_stack import free_port_base
from tests.helpers.transfer_steps import Cell

CLI = [sys.executable, "-m", "sila_labware.cli"]
TRANSFERS = int(os.environ.get("SOAK_TRANSFERS", "50"))
PORT_BASES = range(51600, 51697)  # a block of 4 ports within 51600..51699
PLATE = "plate_001"
A, B = ("station_a", 1), ("station_b", 1)
BRIDGE_NODE = "sila_labware_bridge"

# Bounds, measured from the baseline taken after the first round trip (A->B->A), when every pool,
# cache and lazily created gRPC/DDS thread has been used once (the sample after the first transfer
# is reported too, but the way back still warms up the other station's paths):
# - threads: no process may gain more than 4 threads (noise: a pool thread first needed after the
#   baseline). Finished observable commands keep their results for their lifetime (10 min), but in
#   one thread per server (servers/finished_commands.py); before, sila2 parked one thread per
#   command for that time, 8 per transfer (1,098 threads after 131 transfers). A thread leaked per
#   goal, subscription, gRPC stream or command would exceed the bound by 48.
# - memory: 25 MiB per process, plus 64 KiB per thread gained (about 35 KiB each was measured:
#   touched stack pages and interpreter state). Allocator noise
#   between samples was a few MiB; a leak of what a transfer handles (one 640x480 RGBA frame =
#   1.2 MiB, per-goal feedback messages, a gRPC call state) repeated 48 times would exceed it, so a
#   per-transfer leak of about 0.5 MiB fails here.
THREAD_NOISE = 4
MEMORY_GROWTH_LIMIT_KIB = 25 * 1024
MEMORY_PER_THREAD_KIB = 64
TERMINAL_GOAL_STATES = {GoalStatus.STATUS_SUCCEEDED, GoalStatus.STATUS_CANCELED, GoalStatus.STATUS_ABORTED}


@dataclass(frozen=True)
class ProcessSample:
    """Resident memory and thread count of one process, read from /proc/PID/status."""

    rss_kib: int
    threads: int


def sample(pid: int) -> ProcessSample:
    fields = dict(
        line.split(":", 1) for line in Path(f"/proc/{pid}/status").read_text().splitlines() if ":" in line
    )
    return ProcessSample(int(fields["VmRSS"].split()[0]), int(fields["Threads"]))


class ServedCell(Cell):
    """The transfer steps of `Cell`, against servers another process runs (no Deployment here)."""

    def __init__(self, robot: SilaClient, stations: dict[str, SilaClient]) -> None:
        self.deployment = None  # type: ignore[assignment] - nest sensors are not read in the soak
        self.robot = robot
        self.stations = stations


def wait_for_serving(stdout_path: Path, serve: subprocess.Popen, timeout_s: float) -> str:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        text = stdout_path.read_text()
        if "serving; Ctrl-C stops" in text:
            return text
        assert serve.poll() is None, f"serve ended early with {serve.returncode}"
        time.sleep(0.5)
    raise TimeoutError(f"serve not ready after {timeout_s:.0f} s")


def ros_graph_of_bridge(runtime: RosRuntime) -> dict[str, int]:
    """Publishers, subscriptions and service clients the bridge node holds, seen over DDS."""

    def count() -> dict[str, int]:
        node = runtime.node
        return {
            "publishers": len(node.get_publisher_names_and_types_by_node(BRIDGE_NODE, "/")),
            "subscriptions": len(node.get_subscriber_names_and_types_by_node(BRIDGE_NODE, "/")),
            "service_clients": len(node.get_client_names_and_types_by_node(BRIDGE_NODE, "/")),
            "nodes": len(node.get_node_names()),
        }

    return runtime.call(count)


def unfinished_goals(runtime: RosRuntime, timeout_s: float = 5.0) -> dict[str, int]:
    """Goals of every action in the graph that are not in a terminal state (from _action/status)."""
    latest: dict[str, GoalStatusArray] = {}
    qos = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
    )

    def subscribe() -> tuple[list[str], list]:
        names = [name for name, _types in get_action_names_and_types(runtime.node)]
        subscriptions = [
            runtime.node.create_subscription(
                GoalStatusArray,
                f"{name}/_action/status",
                lambda message, name=name: latest.__setitem__(name, message),
                qos,
            )
            for name in names
        ]
        return names, subscriptions

    names, subscriptions = runtime.call(subscribe)
    deadline = time.monotonic() + timeout_s
    while len(latest) < len(names) and time.monotonic() < deadline:
        time.sleep(0.1)
    runtime.call(lambda: [runtime.node.destroy_subscription(item) for item in subscriptions])
    return {
        name: sum(1 for goal in latest[name].status_list if goal.status not in TERMINAL_GOAL_STATES)
        for name in latest
    }


def summarise_pose_errors(samples: list[dict[str, float]]) -> dict[str, object]:
    """Median, maximum and last value of each error over the transfers, and every sample."""
    summary: dict[str, object] = {"samples": samples}
    for key in ("localised_cm", "localised_deg", "odometry_cm", "odometry_deg"):
        values = sorted(sample[key] for sample in samples if key in sample)
        if values:
            last = next(sample[key] for sample in reversed(samples) if key in sample)
            summary[key] = {"median": values[len(values) // 2], "max": values[-1], "last": last}
    return summary


@pytest.mark.soak
@pytest.mark.timeout(7200)
def test_many_transfers_in_one_serve_process_leak_nothing(tmp_path: Path) -> None:
    fixed_port = os.environ.get("SOAK_PORT_BASE")
    port_base = int(fixed_port) if fixed_port else free_port_base(4, PORT_BASES)
    stdout_path, stderr_path = tmp_path / "serve.out", tmp_path / "serve.err"
    with stdout_path.open("w") as stdout, stderr_path.open("w") as stderr:
        serve = subprocess.Popen(
            [*CLI, "serve", "--insecure", "--no-discovery", "--port-base", str(port_base)],
            stdout=stdout,
            stderr=stderr,
            stdin=subprocess.DEVNULL,
        )
    runtime: RosRuntime | None = None
    try:
        output = wait_for_serving(stdout_path, serve, timeout_s=240)
        children = {name: int(pid) for name, pid in re.findall(r"robot side: (\w+) pid (\d+)", output)}
        assert set(children) == {"sim_node", "sequencer"}, output
        watched = {"serve": serve.pid, **children}
        robot = SilaClient("127.0.0.1", port_base, insecure=True)
        stations = {
            item.Position: SilaClient("127.0.0.1", port_base + 1 + offset, insecure=True)
            for offset, item in enumerate(
                robot.LabwareTransferManipulatorController.AvailableHandoverPositions.get()
            )
        }
        cell = ServedCell(robot, stations)
        runtime = RosRuntime("soak_observer").start()
        pose_probe = PoseErrorProbe(runtime)
        pose_errors: list[dict[str, float]] = []

        started = time.monotonic()
        durations: list[float] = []
        samples: dict[int, dict[str, ProcessSample]] = {}
        graph: dict[int, dict[str, int]] = {}
        failure = ""
        for number in range(1, TRANSFERS + 1):
            source, destination = (A, B) if number % 2 else (B, A)
            began = time.monotonic()
            try:
                cell.transfer(source, destination, PLATE)
            except Exception as error:  # noqa: BLE001 - reported with the figures gathered so far
                failure = f"transfer {number} ({source[0]} -> {destination[0]}) failed: {error}"
                samples[number] = {name: sample(pid) for name, pid in watched.items()}
                graph[number] = ros_graph_of_bridge(runtime)
                break
            durations.append(time.monotonic() - began)
            assert cell.location(PLATE) == (False, destination[0], destination[1])
            pose_errors.append({"transfer": number, **pose_probe.sample()})
            if number <= 2 or number % 5 == 0 or number == TRANSFERS:
                samples[number] = {name: sample(pid) for name, pid in watched.items()}
                graph[number] = ros_graph_of_bridge(runtime)
            print(
                f"transfer {number}: {source[0]} -> {destination[0]} in {durations[-1]:.1f} s; "
                f"pose errors {pose_errors[-1]}",
                flush=True,
            )
        wall_s = time.monotonic() - started

        goals_left = unfinished_goals(runtime)
        last = max(samples)
        baseline, end = samples[2], samples[last]
        report = {
            "transfers": len(durations),
            "failure": failure,
            "wall_s": round(wall_s, 1),
            "transfer_s": {
                "median": round(sorted(durations)[len(durations) // 2], 1),
                "max": round(max(durations), 1),
            },
            "samples": {number: {n: asdict(s) for n, s in by.items()} for number, by in samples.items()},
            "bridge_graph": graph,
            "unfinished_goals": goals_left,
            "robot_state": cell.robot_state(),
            "pose_errors": summarise_pose_errors(pose_errors),
        }
        print(json.dumps(report, indent=1), flush=True)
        if os.environ.get("SOAK_REPORT"):
            Path(os.environ["SOAK_REPORT"]).write_text(json.dumps(report, indent=1) + "\n")
        assert not failure, failure

        assert serve.poll() is None and all(Path(f"/proc/{pid}").exists() for pid in children.values()), (
            "the robot side must not have been restarted during the soak"
        )
        for name in watched:
            thread_growth = end[name].threads - baseline[name].threads
            assert thread_growth <= THREAD_NOISE, (name, baseline[name], end[name])
            memory_growth = end[name].rss_kib - baseline[name].rss_kib
            memory_limit = MEMORY_GROWTH_LIMIT_KIB + MEMORY_PER_THREAD_KIB * max(0, thread_growth)
            assert memory_growth <= memory_limit, f"{name} grew {memory_growth} KiB over the soak"
        assert graph[last] == graph[2], "the bridge's ROS endpoints changed: subscriptions leak"
        assert goals_left and not any(goals_left.values()), f"goals still open: {goals_left}"
        assert cell.robot_state() == "Idle"
    finally:
        if runtime is not None:
            runtime.stop()
        if serve.poll() is None:
            serve.terminate()
            try:
                serve.wait(15)
            except subprocess.TimeoutExpired:
                serve.kill()
                serve.wait(5)
