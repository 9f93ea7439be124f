"""Real processes over DDS for the ROS tests: start sim_node (+ sequencer), talk to them, stop them.

The child processes inherit ROS_DOMAIN_ID and ROS_AUTOMATIC_DISCOVERY_RANGE from the test run
(tests/conftest.py). `RosCaller` is a single-threaded client: every call sends a request and
spins its own executor on the calling thread until the answer arrives, so no rclpy object is
ever touched by two threads.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import rclpy
from rclpy.action import ActionClient
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from ros_bridge.actions import cancel_nobodys_goal

REPO = Path(__file__).resolve().parents[2]


@contextmanager
def running(module: str, *args: str, log_path: Path) -> Iterator[subprocess.Popen]:
    """Run `python -m module args...` with output to log_path; always stopped at the end."""
    with open(log_path, "w") as log:
        process = subprocess.Popen(
            [sys.executable, "-m", module, *args],
            cwd=REPO,
            stdout=log,
            stderr=subprocess.STDOUT,
            env=dict(os.environ, PYTHONUNBUFFERED="1"),
        )
        try:
            yield process
        finally:
            stop(process)


def stop(process: subprocess.Popen, timeout_s: float = 10.0) -> int:
    """SIGTERM, then SIGKILL if it does not exit in time; returns the exit code."""
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=5.0)
    return process.returncode


@dataclass
class GoalOutcome:
    status: int
    result: Any
    feedback: list[Any] = field(default_factory=list)
    feedback_times: list[float] = field(default_factory=list)


class RosCaller:
    """Actions, services and topics from the test's own thread (one executor, spun here)."""

    def __init__(self, name: str = "ros_test_client") -> None:
        if not rclpy.ok():
            rclpy.init()
        self.node = rclpy.create_node(name)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self._action_clients: dict[str, ActionClient] = {}
        self.latest: dict[str, Any] = {}

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()

    def spin_until(self, future: Any, timeout_s: float) -> Any:
        self.executor.spin_until_future_complete(future, timeout_sec=timeout_s)
        if not future.done():
            raise TimeoutError(f"no answer within {timeout_s} s")
        return future.result()

    def spin_for(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.05)

    def wait_for(self, condition: Callable[[], bool], timeout_s: float, what: str) -> None:
        end = time.monotonic() + timeout_s
        while not condition():
            if time.monotonic() > end:
                raise TimeoutError(f"timed out waiting for {what}")
            self.executor.spin_once(timeout_sec=0.05)

    def subscribe(self, message_type: Any, topic: str, latched: bool = False) -> Any:
        """Keep the latest message of `topic` in `latest` (`latched`: a transient-local topic's last
        message too); returns the subscription (to destroy)."""
        durability = DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE
        qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE, durability=durability)
        return self.node.create_subscription(
            message_type, topic, lambda msg: self.latest.__setitem__(topic, msg), qos
        )

    def action_client(self, action_type: Any, name: str, timeout_s: float = 30.0) -> ActionClient:
        """A client of `name` once its server answers a request, not only once it is discovered: the
        server may not yet know this client's reply readers then, and a goal's answer sent too
        early is lost (test_sequencer_bounds waited 30 s for one, once, in a loaded CI run)."""
        if name not in self._action_clients:
            client = ActionClient(self.node, action_type, name)
            self.wait_for(
                lambda: client.server_is_ready() and self._answers(client), timeout_s, f"action server {name}"
            )
            self._action_clients[name] = client
        return self._action_clients[name]

    def _answers(self, client: ActionClient) -> bool:
        future = cancel_nobodys_goal(client)
        self.executor.spin_until_future_complete(future, timeout_sec=1.0)
        if not future.done():
            client._remove_pending_cancel_request(future)  # an unanswered probe is withdrawn
        return future.done()

    def send(self, action_type: Any, name: str, goal: Any, timeout_s: float = 30.0) -> Any:
        """Send a goal and return its handle once accepted or rejected."""
        client = self.action_client(action_type, name)
        self._outcome = GoalOutcome(0, None)
        outcome = self._outcome

        def on_feedback(message: Any) -> None:
            outcome.feedback.append(message.feedback)
            outcome.feedback_times.append(time.monotonic())

        handle = self.spin_until(client.send_goal_async(goal, feedback_callback=on_feedback), timeout_s)
        handle.outcome = outcome
        return handle

    def result(self, handle: Any, timeout_s: float) -> GoalOutcome:
        response = self.spin_until(handle.get_result_async(), timeout_s)
        handle.outcome.status = response.status
        handle.outcome.result = response.result
        return handle.outcome

    def call_action(self, action_type: Any, name: str, goal: Any, timeout_s: float = 120.0) -> GoalOutcome:
        handle = self.send(action_type, name, goal)
        assert handle.accepted, f"goal to {name} rejected"
        return self.result(handle, timeout_s)

    def call_service(self, service_type: Any, name: str, request: Any, timeout_s: float = 30.0) -> Any:
        client = self.node.create_client(service_type, name)
        self.wait_for(client.service_is_ready, timeout_s, f"service {name}")
        try:
            return self.spin_until(client.call_async(request), timeout_s)
        finally:
            self.node.destroy_client(client)


@contextmanager
def robot_side(logs: Path, caller_name: str, *twin_arguments: str) -> Iterator[RosCaller]:
    """tiago_twin (with `twin_arguments`) and the sequencer as real processes, and a caller.
    Both must still run when the block ends, then stop cleanly on SIGTERM, logging no traceback."""
    with (
        running("tiago_twin", *twin_arguments, log_path=logs / "sim_node.log") as sim,
        running("tiago_sim.sequencer", log_path=logs / "sequencer.log") as sequencer,
    ):
        caller = RosCaller(caller_name)
        try:
            yield caller
        finally:
            caller.close()
            for process, name in ((sim, "sim_node"), (sequencer, "sequencer")):
                assert process.poll() is None, f"{name} died early; see {logs / (name + '.log')}"
    for process, name in ((sim, "sim_node"), (sequencer, "sequencer")):
        assert process.returncode == 0, f"{name} did not exit cleanly on SIGTERM: {process.returncode}"
        assert "Traceback" not in (logs / f"{name}.log").read_text(), f"{name} logged a traceback"
