"""A /describe_workcell that does not answer until told to, run as its own process.

For the sequencer's bounded waits: each request prints "REQUEST n" and is held (each on its own
thread) until the file given as `--answer-when` exists, then answered with one station. Prints
"READY" once the service exists. Publishes nothing else: no robot state ever comes.
"""

from __future__ import annotations

import argparse
import sys
import threading
import time
from pathlib import Path

import rclpy
from labware_interfaces.msg import StationInfo
from labware_interfaces.srv import DescribeWorkcell
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from ros_bridge.latency_peer import serve_node


class SilentWorkcell(Node):
    def __init__(self, answer_when: Path) -> None:
        super().__init__("silent_workcell")
        self._answer_when = answer_when
        self._requests = 0
        self._lock = threading.Lock()
        self.create_service(
            DescribeWorkcell, "/describe_workcell", self._describe, callback_group=ReentrantCallbackGroup()
        )

    def _describe(self, _request: DescribeWorkcell.Request, response: DescribeWorkcell.Response):
        with self._lock:
            self._requests += 1
            print(f"REQUEST {self._requests}", flush=True)
        while not self._answer_when.exists():
            time.sleep(0.02)
        response.stations = [StationInfo(name="station_a", sub_positions=2, poi="station_a_work")]
        response.hotel_slots, response.pois, response.dock_poi = 2, ["station_a_work", "dock"], "dock"
        response.nest_sensors = response.hotel_sensors = response.label_readers = True
        return response


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--answer-when", type=Path, required=True)
    args = parser.parse_args()
    rclpy.init()
    return serve_node(SilentWorkcell(args.answer_when))


if __name__ == "__main__":
    sys.exit(main())
