"""What the skills cost over the robot's own ROS 2 interfaces: one demo transfer per adapter, timed,
with the CPU of every process and (over the ROS adapter) the messages of every topic counted.

    python -m tiago_sim.measuring.ros_adapter_load [--rounds N] [--paces X ...]

Why: the skills reach the twin in-process (the hardware port on the sim thread) for campaigns, and
over DDS through tiago_ros_hardware as they would a real TIAGo++. This prints, per adapter, the
robot time, the wall time and their ratio (the real-time factor), and the CPU seconds of the
whole deployment (every robot-side process and the SiLA side, from the demo's rusage); for the
ROS adapter also each topic's messages a second of wall time, counted by a node of this process
in the demo's ROS domain (it subscribes to every topic it discovers, raw, as the run goes on; but
the head camera's and the laser's, which the simulator renders and casts only while someone
listens, so a counter listening to them would add to what it measures).
Each adapter runs at the paces given (`--paces`; pace 1 is a real robot's timing, where waiting
on messages costs the robot time it costs the wall); the in-process one also unpaced. The sim's
clock runs at the pace while the robot waits too, so at pace 5 every wall second the adapter waits
shows as five seconds of robot time.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import random
import resource
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from robot_port.tiago_interfaces import LASER

CLI = str(Path(sys.executable).with_name("sila-labware"))
DISCOVERY_PERIOD_S = 0.5


def _message_type(name: str) -> Any:
    """The Python class of a type name as the graph reports it (an action's feedback and status
    messages too: `pkg/action/Name_FeedbackMessage`)."""
    package, kind, type_name = name.split("/")
    module = importlib.import_module(f"{package}.{kind}")
    if kind == "action" and type_name.endswith("_FeedbackMessage"):
        return getattr(module, type_name.removesuffix("_FeedbackMessage")).Impl.FeedbackMessage
    return getattr(module, type_name)


UNCOUNTED = ("/head_front_camera/", LASER)
"""Topics a counting subscriber would make the simulator produce (renders cost 0.1 s of CPU each)."""


class TopicCounter:
    """Counts every topic's messages in this process's ROS domain, subscribing as topics appear
    (but UNCOUNTED)."""

    def __init__(self) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.qos import QoSProfile, ReliabilityPolicy

        rclpy.init()
        self.node = rclpy.create_node("topic_counter")
        self.counts: Counter[str] = Counter()
        self._qos = QoSProfile(depth=50, reliability=ReliabilityPolicy.BEST_EFFORT)
        self._subscribed: set[str] = set()
        self._executor = SingleThreadedExecutor()
        self._executor.add_node(self.node)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        next_discovery = 0.0
        while not self._stop.is_set():
            if time.monotonic() >= next_discovery:
                self._discover()
                next_discovery = time.monotonic() + DISCOVERY_PERIOD_S
            self._executor.spin_once(timeout_sec=0.05)

    def _discover(self) -> None:
        for topic, types in self.node.get_topic_names_and_types():
            if topic in self._subscribed or not types or topic.startswith(("/rosout", *UNCOUNTED)):
                continue
            self._subscribed.add(topic)
            try:
                kind = _message_type(types[0])
            except (ImportError, AttributeError, ValueError):
                continue
            self.node.create_subscription(
                kind, topic, lambda _raw, topic=topic: self.counts.update([topic]), self._qos, raw=True
            )

    def close(self) -> None:
        import rclpy

        self._stop.set()
        self._thread.join(timeout=5.0)
        self.node.destroy_node()
        rclpy.shutdown()


def run_demo(arguments: Sequence[str]) -> tuple[dict, float]:
    """One `sila-labware demo --json` with `arguments`; its report and the CPU seconds of its process tree."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    port_base = random.randrange(52000, 60000, 20)
    logs = tempfile.mkdtemp(prefix="ros-adapter-load-")  # kept: a failed run's logs say why
    done = subprocess.run(
        [
            CLI,
            "demo",
            "--json",
            "--insecure",
            "--no-discovery",
            "--port-base",
            str(port_base),
            "--log-dir",
            logs,
            *arguments,
        ],
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    report = json.loads(done.stdout)
    if not report.get("success"):
        raise RuntimeError(f"the demo failed: {report.get('error')} (logs in {logs})")
    return report, cpu


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m tiago_sim.measuring.ros_adapter_load", description=__doc__.split("\n")[0]
    )
    parser.add_argument("--rounds", type=int, default=1, help="transfers per adapter (default: %(default)s)")
    parser.add_argument(
        "--paces",
        type=float,
        nargs="+",
        default=[5.0, 1.0],
        help="paces to run both adapters at (default: 5 1)",
    )
    args = parser.parse_args(argv)
    domain = random.randrange(110, 200)
    os.environ["ROS_DOMAIN_ID"] = str(domain)
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    runs: dict[str, list[str]] = {"in-process, unpaced": []}
    for pace in args.paces:
        runs[f"in-process, pace {pace:g}"] = ["--pace", str(pace)]
        runs[f"ROS adapter, pace {pace:g}"] = ["--ros-adapter", "--pace", str(pace)]
    rates: dict[str, Counter[str]] = {}  # per ROS adapter run: messages a second of wall time
    header = "| adapter | robot time s | wall s | real-time factor | CPU s per transfer |"
    sys.stdout.write(f"{header}\n|---|---:|---:|---:|---:|\n")
    for label, arguments in runs.items():
        for _ in range(args.rounds):
            counter = TopicCounter() if "--ros-adapter" in arguments else None
            started = time.monotonic()
            try:
                report, cpu = run_demo([*arguments, "--domain-id", str(domain)])
            finally:
                if counter is not None:
                    counter.close()
            if counter is not None:
                seconds = (time.monotonic() - started) * args.rounds
                rates.setdefault(label, Counter()).update({t: n / seconds for t, n in counter.counts.items()})
            sim, wall = report["sim_seconds"], report["wall_seconds"]
            sys.stdout.write(f"| {label} | {sim:.1f} | {wall:.1f} | {sim / wall:.2f} | {cpu:.1f} |\n")
            sys.stdout.flush()
    labels = list(rates)
    sys.stdout.write(
        "\nMessages a second of wall time over the ROS adapter (the whole demo, start-up included):\n\n"
    )
    sys.stdout.write("| topic | " + " | ".join(labels) + " |\n|---|" + "---:|" * len(labels) + "\n")
    topics = sorted({t for counts in rates.values() for t in counts}, key=lambda t: -rates[labels[0]][t])
    for topic in topics:
        sys.stdout.write(
            f"| `{topic}` | " + " | ".join(f"{rates[label][topic]:.1f}" for label in labels) + " |\n"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
