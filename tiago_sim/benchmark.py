"""Benchmark: one plate transfer A -> B through the ROS actions, timed.

    python -m tiago_sim.benchmark [--world FILE] [--seed N] [--from station_a] [--to station_b]

Starts sim_node and sequencer as child processes (own ROS domain unless ROS_DOMAIN_ID is set),
runs GetLabware at the source and PutLabware at the destination, and prints simulated and wall
time, the real-time factor, wall time per phase (from the task feedback), the placement error
and the marker pose error against ground truth. Ground truth (the world file and the
/check_placement service) is used here only to measure.
"""

from __future__ import annotations

import argparse
import math
import os
import random
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Any


def _start(module: str, args: list[str], log_dir: Path) -> subprocess.Popen:
    log = open(log_dir / f"{module.rsplit('.', 1)[-1]}.log", "w")  # noqa: SIM115 - closed with the process
    return subprocess.Popen([sys.executable, "-m", module, *args], stdout=log, stderr=subprocess.STDOUT)


def _stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.kill()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tiago_sim.benchmark", description=__doc__.split("\n")[0])
    parser.add_argument("--world", type=Path, default=None)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--from", dest="source", default="station_a")
    parser.add_argument("--to", dest="destination", default="station_b")
    args = parser.parse_args(argv)
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.SystemRandom().randint(150, 200)))
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

    import numpy as np
    import rclpy
    from geometry_msgs.msg import Pose2D
    from labware_interfaces.action import GetLabware, PutLabware
    from labware_interfaces.srv import CheckPlacement
    from rclpy.action import ActionClient
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock

    from tiago_sim import transforms as tf
    from tiago_sim.world import DEFAULT_WORLD, load_world

    world = load_world(args.world or DEFAULT_WORLD)
    plate = next(p for p in world.plates if p.station == args.source)
    world_args = ["--world", str(args.world or DEFAULT_WORLD)]
    log_dir = Path(tempfile.mkdtemp(prefix="tiago_benchmark_"))
    sim = _start(
        "tiago_sim.sim_node", [*world_args, "--seed", str(args.seed), "--log-level", "INFO"], log_dir
    )
    sequencer = _start("tiago_sim.sequencer", world_args, log_dir)
    rclpy.init()
    node = rclpy.create_node("tiago_benchmark")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    clock: dict[str, float] = {}
    qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    truth: dict[str, Any] = {}
    node.create_subscription(Pose2D, "/ground_truth/base_pose", lambda m: truth.__setitem__("now", m), qos)
    node.create_subscription(
        Clock, "/clock", lambda m: clock.__setitem__("t", m.clock.sec + m.clock.nanosec * 1e-9), qos
    )

    def wait(future: Any, timeout_s: float) -> Any:
        executor.spin_until_future_complete(future, timeout_sec=timeout_s)
        if not future.done():
            raise TimeoutError("no answer")
        return future.result()

    try:
        tasks = ((GetLabware, "/get_labware"), (PutLabware, "/put_labware"))
        clients = {kind: ActionClient(node, kind, name) for kind, name in tasks}
        end = time.monotonic() + 60
        while not all(c.server_is_ready() for c in clients.values()) or "t" not in clock:
            if time.monotonic() > end:
                raise TimeoutError("robot did not come up")
            executor.spin_once(timeout_sec=0.1)
        phase_wall: dict[str, float] = defaultdict(float)
        sim_start, wall_start = clock["t"], time.monotonic()
        for kind, station in ((GetLabware, args.source), (PutLabware, args.destination)):
            goal = kind.Goal(
                handover_position=station, sub_position=1, internal_position=1, labware_id=plate.labware_id
            )
            last = {"phase": "", "t": time.monotonic()}

            def on_feedback(message: Any, last: dict = last, task: str = kind.__name__) -> None:
                now = time.monotonic()
                if last["phase"]:
                    phase_wall[f"{task}: {last['phase'].split(':')[0]}"] += now - last["t"]
                last["phase"], last["t"] = message.feedback.phase, now

            handle = wait(clients[kind].send_goal_async(goal, feedback_callback=on_feedback), 30)
            result = wait(handle.get_result_async(), 600).result
            print(f"{kind.__name__} {station}: success={result.success} {result.error_code} {result.message}")
            if not result.success:
                return 1
            executor.spin_once(timeout_sec=0.6)
            truth[station] = truth.get("now")  # the base stood here through the manipulation
        executor.spin_once(timeout_sec=0.2)
        sim_s, wall_s = clock["t"] - sim_start, time.monotonic() - wall_start
        check_client = node.create_client(CheckPlacement, "/check_placement")
        check = wait(check_client.call_async(CheckPlacement.Request(
            labware_id=plate.labware_id, station=args.destination, sub_position=1)), 30)  # fmt: skip
        print(f"simulated {sim_s:.1f} s, wall {wall_s:.1f} s, real-time factor {sim_s / wall_s:.1f}")
        print("wall time per phase:")
        for phase, seconds in phase_wall.items():
            print(f"  {phase:<32} {seconds:6.2f} s")
        print(f"placement: in_nest={check.in_nest} error {check.position_error_m * 1000:.2f} mm, "
              f"yaw {math.degrees(check.yaw_error_rad):.2f} deg")  # fmt: skip
        _marker_errors(log_dir / "sim_node.log", world, truth, np, tf)
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.shutdown()
        _stop(sequencer)
        _stop(sim)
    return 0


def _marker_errors(log_path: Path, world: Any, truth: dict[str, Any], np: Any, tf: Any) -> None:
    """Marker positions the robot perceived (sim_node log) against ground truth.

    Truth: the marker pose from the world file seen from the true base pose that the sim node
    publishes on /ground_truth/base_pose (taken while the base stood at the station).
    """
    for line in log_path.read_text().splitlines():
        if "tiago_sim.marker_motion: marker" not in line:
            continue
        station = world.station(line.split(" of ", 1)[1].split()[0])
        base = truth.get(station.name)
        if base is None:
            continue
        seen = np.array([float(v) for v in line.split("[")[1].split("]")[0].split()])
        T_base_marker = tf.invert(tf.from_planar(base.x, base.y, base.theta)) @ station.T_world_marker()
        print(f"marker {station.marker_id} ({station.name}): position error "
              f"{np.linalg.norm(seen - T_base_marker[:3, 3]) * 1000:.2f} mm")  # fmt: skip


if __name__ == "__main__":
    sys.exit(main())
