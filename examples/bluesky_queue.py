"""Queue the labware robot's plans on bluesky-queueserver, run them, and print how each ended.

The queue server must be running with the robot's startup profile, against a running robot side:

    ./run serve                                               # prints its ROS domain, e.g. 42
    python -m ros_bridge.bluesky.queueserver --domain-id 42   # Redis and the RE Manager
    python examples/bluesky_queue.py

The queue: the plate fetched to the beam by two robot tasks, a measurement queued on its own
(`count`), the plate brought back by two more, then the whole sample exchange as one plan.
Exit code 0 only if every queued plan completed.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from bluesky_queueserver_api import BPlan
from bluesky_queueserver_api.zmq import REManagerAPI

MEASURE_POSITION_M = 0.26  # the beamline paper moved its stage by 26 cm
LOAD_POSITION_M = 0.0

QUEUE = [
    BPlan("robot_task_plan", "robot", "pickup"),
    BPlan("robot_task_plan", "robot", "place"),
    BPlan("count", ["detector"], num=3),
    BPlan("robot_task_plan", "robot", "return_pickup"),
    BPlan("robot_task_plan", "robot", "return_place"),
    BPlan(
        "sample_exchange_plan",
        "robot",
        "stage",
        "detector",
        measure_position=MEASURE_POSITION_M,
        load_position=LOAD_POSITION_M,
    ),
]


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--zmq-control-addr", default="tcp://127.0.0.1:60615")
    parser.add_argument("--zmq-info-addr", default="tcp://127.0.0.1:60625")
    parser.add_argument("--timeout", type=float, default=900.0, help="seconds the whole queue may take")
    args = parser.parse_args(argv)

    manager = REManagerAPI(zmq_control_addr=args.zmq_control_addr, zmq_info_addr=args.zmq_info_addr)
    try:
        if not manager.status()["worker_environment_exists"]:
            manager.environment_open()  # runs the profile: connects to the robot, builds the devices
            manager.wait_for_idle(timeout=120.0)
        if not manager.status()["worker_environment_exists"]:
            print("the worker environment did not open: see the queue server's output", file=sys.stderr)
            return 1
        manager.queue_clear()
        for plan in QUEUE:
            manager.item_add(plan)  # validated by the queue server: a bad plan is refused here
        done_before = len(manager.history_get()["items"])
        manager.queue_start()
        manager.wait_for_idle(timeout=args.timeout)
        ended = manager.history_get()["items"][done_before:]
        for item in ended:
            result = item["result"]
            print(f"{item['name']} {item.get('args', [])}: {result['exit_status']} {result.get('msg', '')}")
        manager.environment_close()
        manager.wait_for_idle(timeout=60.0)
    finally:
        manager.close()
    completed = [item for item in ended if item["result"]["exit_status"] == "completed"]
    return 0 if len(completed) == len(QUEUE) else 1


if __name__ == "__main__":
    sys.exit(main())
