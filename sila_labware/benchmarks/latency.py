"""Latency of the SiLA-ROS bridge, beside a plain rclpy action call, and serve's discovery time.

    python -m sila_labware.benchmarks.latency [--calls N] [--feedbacks F] [--json] [--no-discovery]

What is measured (all with `time.monotonic()`, one clock for every process on this machine):
- goal accept: from a client starting the call to the action server accepting the ROS goal.
  SiLA path: a `unitelabs-sila` client calls MobileRobotController.DriveToPointOfInterest on our
  robot server, which sends /navigate_to_poi through the bridge. rclpy path: the bridge's own
  ActionCaller sends the same goal with no SiLA in between.
- feedback: from the action server publishing a feedback message to the client seeing that
  progress value (SiLA: in the command's execution-info stream; rclpy: in the feedback callback).
- discovery: from launching `sila-labware serve` (TLS, discovery on, the real simulation) to
  every server it lists being resolvable over mDNS (see `sila_labware.benchmarks.discovery_timing`).

The action server is `ros_bridge.latency_peer` in a child process (no physics), so the figures
are the bridge's own cost. The SiLA server and client share this process (unencrypted,
127.0.0.1), as do the bridge's ROS thread and the rclpy client.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import logging
import math
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

from labware_interfaces.action import NavigateToPoi
from labware_interfaces.srv import DescribeWorkcell
from sila.client import Client, ClientConfig

from ros_bridge.actions import ActionCaller, GoalProgress
from ros_bridge.domain import reserve_domain_id
from ros_bridge.latency_peer import STATION_POI
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime
from ros_bridge.services import ServiceCaller
from sila_labware.benchmarks.child_lines import ChildLines, ChildSilent
from sila_labware.benchmarks.discovery_timing import time_serve_until_discoverable
from sila_labware.deployment.processes import ros_environment
from sila_labware.deployment.stack import join_ros_domain
from sila_labware.device.robot_controller import RobotController
from sila_labware.servers.robot_server.server import Server as RobotServer
from sila_labware.servers.serving import start_sila_server, stop_sila_server

logger = logging.getLogger(__name__)

DEFAULT_WORLD = Path(__file__).resolve().parents[2] / "lab_description" / "worlds" / "default.yaml"
PEER_START_TIMEOUT_S = 60.0


@dataclass(frozen=True)
class Percentiles:
    """Milliseconds over `samples` measurements."""

    samples: int
    p50_ms: float
    p99_ms: float
    max_ms: float


@dataclass(frozen=True)
class LatencyReport:
    calls: int
    feedbacks_per_call: int
    sila_goal_accept: Percentiles
    rclpy_goal_accept: Percentiles
    sila_feedback: Percentiles
    rclpy_feedback: Percentiles
    serve_servers: int | None = None
    serve_printed_s: float | None = None
    serve_discoverable_s: float | None = None

    def as_json_object(self) -> dict[str, Any]:
        return asdict(self)


def percentiles(seconds: Sequence[float]) -> Percentiles:
    """p50 and p99 (linear interpolation between closest ranks) of durations given in seconds."""
    if not seconds:
        return Percentiles(0, math.nan, math.nan, math.nan)
    ordered = sorted(value * 1000.0 for value in seconds)

    def at(fraction: float) -> float:
        position = fraction * (len(ordered) - 1)
        low = math.floor(position)
        high = min(low + 1, len(ordered) - 1)
        return ordered[low] + (ordered[high] - ordered[low]) * (position - low)

    return Percentiles(len(ordered), round(at(0.5), 3), round(at(0.99), 3), round(ordered[-1], 3))


class _Peer:
    """The latency peer child; its per-goal JSON lines are read as they come, each with a bound."""

    def __init__(self, domain_id: int, feedbacks: int) -> None:
        command = [sys.executable, "-m", "ros_bridge.latency_peer", "--feedbacks", str(feedbacks)]
        self.process = subprocess.Popen(
            command, stdout=subprocess.PIPE, text=True, env=ros_environment(domain_id)
        )
        assert self.process.stdout is not None
        self._lines = ChildLines(self.process.stdout, "the latency peer")
        try:
            ready = self._lines.next_line(PEER_START_TIMEOUT_S)
        except ChildSilent:
            ready = None
        if ready is None or ready.strip() != "READY":
            self.stop()
            raise RuntimeError(f"latency peer did not start within {PEER_START_TIMEOUT_S:.0f} s")

    def next_goal(self, timeout_s: float = 10.0) -> dict[str, Any]:
        line = self._lines.next_line(timeout_s)
        if line is None:
            raise RuntimeError(f"the latency peer ended (exit code {self.process.poll()})")
        return json.loads(line)

    def stop(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(timeout=5.0)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait(timeout=5.0)


def _feedback_delays(
    sent: Sequence[Sequence[float]], seen: dict[float, float], listening_since: float
) -> list[float]:
    """Delay of each feedback the client saw, matched by its progress value. Feedback sent before
    the client was listening is left out (it would count the subscription's set-up). Progress
    travels as float32, hence the tolerance."""
    delays = []
    for progress, sent_at in sent:
        for seen_progress, seen_at in seen.items():
            if abs(seen_progress - progress) < 1e-5 and sent_at >= listening_since:
                delays.append(seen_at - sent_at)
    return delays


def measure_rclpy(runtime: RosRuntime, peer: _Peer, calls: int) -> tuple[list[float], list[float]]:
    """Goal-accept and feedback delays of direct action calls (the bridge's ActionCaller)."""
    caller = ActionCaller(runtime, NavigateToPoi, "/navigate_to_poi")
    caller.wait_for_server(10.0)
    accepts: list[float] = []
    feedbacks: list[float] = []
    for _call in range(calls):
        seen: dict[float, float] = {}

        def on_feedback(progress: GoalProgress, seen: dict[float, float] = seen) -> None:
            seen.setdefault(progress.progress, time.monotonic())

        started = time.monotonic()
        outcome = caller.run(NavigateToPoi.Goal(poi=STATION_POI), timeout_s=10.0, on_feedback=on_feedback)
        if not outcome.success:
            raise RuntimeError(f"bench goal failed: {outcome}")
        goal = peer.next_goal()
        accepts.append(goal["accepted_at"] - started)
        feedbacks += _feedback_delays(goal["feedback"], seen, started)
    caller.destroy()
    return accepts, feedbacks


async def measure_sila(port: int, peer: _Peer, calls: int) -> tuple[list[float], list[float]]:
    """Goal-accept and feedback delays through the robot SiLA server, seen by unitelabs-sila."""
    client = Client(ClientConfig("127.0.0.1", port, tls=False, default_timeout=30_000))
    await client.open()
    accepts: list[float] = []
    feedbacks: list[float] = []
    try:
        drive = client.MobileRobotController.DriveToPointOfInterest
        for _call in range(calls):
            seen: dict[float, float] = {}
            started = time.monotonic()
            execution = await drive(PointOfInterest=STATION_POI)
            stream = await execution.subscribe_status()
            listening_since = time.monotonic()
            async for status in stream:
                if status.progress is not None:
                    seen.setdefault(status.progress.value, time.monotonic())
            await execution.get_responses()
            goal = peer.next_goal()
            accepts.append(goal["accepted_at"] - started)
            feedbacks += _feedback_delays(goal["feedback"], seen, listening_since)
    finally:
        await client.close()
    return accepts, feedbacks


def run_latency_bench(
    calls: int,
    feedbacks: int = 5,
    discovery: bool = True,
    world: Path = DEFAULT_WORLD,
    port_base: int = 51780,
) -> LatencyReport:
    """Everything above, in this order: rclpy calls, SiLA calls, then serve's discovery time."""
    domain_id = reserve_domain_id()
    join_ros_domain(domain_id)
    peer = _Peer(domain_id, feedbacks)
    runtime = RosRuntime("latency_bench", domain_id=domain_id).start()
    server: RobotServer | None = None
    try:
        link = RobotLink(runtime)
        # A request sent before discovery completes can be lost: wait for the service first.
        ServiceCaller(runtime, DescribeWorkcell, "/describe_workcell").wait_for_service(30.0)
        robot = RobotController(link, link.describe_workcell(timeout_s=10.0))
        rclpy_accepts, rclpy_feedbacks = measure_rclpy(runtime, peer, calls)
        server = RobotServer(robot)
        start_sila_server(server, "127.0.0.1", port_base, authority=None, discovery=False)
        sila_accepts, sila_feedbacks = asyncio.run(measure_sila(port_base, peer, calls))
    finally:
        if server is not None:
            stop_sila_server(server, grace_period=0.2)
        runtime.stop(timeout_s=1.0)
        peer.stop()
    report = LatencyReport(
        calls,
        feedbacks,
        percentiles(sila_accepts),
        percentiles(rclpy_accepts),
        percentiles(sila_feedbacks),
        percentiles(rclpy_feedbacks),
    )
    if not discovery:
        return report
    with tempfile.TemporaryDirectory(prefix="latency-bench-") as scratch:
        timing = time_serve_until_discoverable(world, port_base + 1, Path(scratch) / "ca.pem")
    return replace(
        report,
        serve_servers=timing.servers,
        serve_printed_s=round(timing.printed_s, 3),
        serve_discoverable_s=round(timing.discoverable_s, 3),
    )


def format_report(report: LatencyReport) -> str:
    rows = [
        ("SiLA call -> ROS goal accepted", report.sila_goal_accept),
        ("rclpy call -> ROS goal accepted", report.rclpy_goal_accept),
        ("ROS feedback -> SiLA client progress", report.sila_feedback),
        ("ROS feedback -> rclpy feedback callback", report.rclpy_feedback),
    ]
    lines = [f"{'path':42} {'n':>5} {'p50 ms':>8} {'p99 ms':>8} {'max ms':>8}"]
    for name, figures in rows:
        lines.append(
            f"{name:42} {figures.samples:5d} "
            f"{figures.p50_ms:8.2f} {figures.p99_ms:8.2f} {figures.max_ms:8.2f}"
        )
    if report.serve_discoverable_s is not None:
        lines.append(
            f"serve start -> all {report.serve_servers} servers discoverable: "
            f"{report.serve_discoverable_s:.2f} s "
            f"(server list printed after {report.serve_printed_s:.2f} s)"
        )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m sila_labware.benchmarks.latency", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--calls", type=int, default=200, help="calls per path (default: %(default)s)")
    parser.add_argument("--feedbacks", type=int, default=5, help="feedback messages per goal")
    parser.add_argument("--world", type=Path, default=DEFAULT_WORLD, help="world for the discovery timing")
    parser.add_argument(
        "--port-base", type=int, default=51780, help="bench server port; serve uses the next ones"
    )
    parser.add_argument("--no-discovery", action="store_true", help="skip the serve discovery timing")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    if args.calls < 1 or args.feedbacks < 1:
        parser.error("--calls and --feedbacks must be at least 1")
    logging.basicConfig(level=logging.WARNING)
    report = run_latency_bench(args.calls, args.feedbacks, not args.no_discovery, args.world, args.port_base)
    print(json.dumps(report.as_json_object()) if args.json else format_report(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
