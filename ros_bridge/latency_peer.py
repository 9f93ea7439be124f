"""A pretend robot side that timestamps what the bridge's latency depends on, run as a child process.

    python -m ros_bridge.latency_peer [--feedbacks N] [--feedback-period-s S]

Serves /navigate_to_poi (accepts every goal, then sends N feedback messages with progress
k/(N+1) and succeeds), /describe_workcell (one station, its POI) and /robot_state (idle, 20 Hz),
so that no physics sits between a caller and the action server. For each goal it prints one line
of JSON on stdout: when the goal was accepted and when each feedback was published, as
`time.monotonic()` values, a clock shared by every process on this machine.
Prints "READY" once everything is created.

Threads: one MultiThreadedExecutor; goal and execute callbacks run on its threads.
"""

from __future__ import annotations

import argparse
import json
import sys
import threading
import time
from typing import Any

import rclpy
from labware_interfaces.action import NavigateToPoi
from labware_interfaces.msg import RobotState, StationInfo
from labware_interfaces.srv import DescribeWorkcell
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node

STATION, STATION_POI, OTHER_POI = "bench_station", "bench_station_poi", "bench_elsewhere"


class LatencyPeer(Node):
    """One action, one service, one state topic; every goal is logged with its timestamps."""

    def __init__(self, feedbacks: int, feedback_period_s: float) -> None:
        super().__init__("latency_peer")
        self._feedbacks = feedbacks
        self._feedback_period_s = feedback_period_s
        self._accepted_at: dict[bytes, float] = {}
        self._print_lock = threading.Lock()
        group = ReentrantCallbackGroup()
        self._action_server = ActionServer(
            self,
            NavigateToPoi,
            "/navigate_to_poi",
            execute_callback=self._execute,
            goal_callback=self._on_goal,
            cancel_callback=lambda _handle: CancelResponse.ACCEPT,
            callback_group=group,
        )
        self._service = self.create_service(
            DescribeWorkcell, "/describe_workcell", self._describe, callback_group=group
        )
        self._state_publisher = self.create_publisher(RobotState, "/robot_state", 1)
        self._timer = self.create_timer(0.05, self._publish_state, callback_group=group)

    def _on_goal(self, _request: Any) -> GoalResponse:
        # The goal id is not known here; the execute callback pairs the time with the goal.
        self._last_accepted_at = time.monotonic()
        return GoalResponse.ACCEPT

    def _describe(self, _request: Any, response: DescribeWorkcell.Response) -> DescribeWorkcell.Response:
        response.stations = [StationInfo(name=STATION, sub_positions=1, poi=STATION_POI)]
        response.hotel_slots = 1
        response.pois = [STATION_POI, OTHER_POI]
        response.dock_poi = OTHER_POI
        return response

    def _publish_state(self) -> None:
        message = RobotState(state=RobotState.STATE_IDLE, current_poi="")
        message.stamp = self.get_clock().now().to_msg()
        self._state_publisher.publish(message)

    def _execute(self, goal_handle: Any) -> NavigateToPoi.Result:
        accepted_at = self._last_accepted_at
        feedback_sent_at: list[tuple[float, float]] = []
        for index in range(1, self._feedbacks + 1):
            progress = index / (self._feedbacks + 1)
            time.sleep(self._feedback_period_s)
            sent_at = time.monotonic()
            goal_handle.publish_feedback(
                NavigateToPoi.Feedback(
                    progress=progress, phase="bench", remaining_time_s=(self._feedbacks - index) * 0.01
                )
            )
            feedback_sent_at.append((progress, sent_at))
        goal_handle.succeed()
        with self._print_lock:
            print(
                json.dumps(
                    {"poi": goal_handle.request.poi, "accepted_at": accepted_at, "feedback": feedback_sent_at}
                ),
                flush=True,
            )
        return NavigateToPoi.Result(success=True, message="bench goal done")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--feedbacks", type=int, default=5)
    parser.add_argument("--feedback-period-s", type=float, default=0.02)
    args = parser.parse_args()
    rclpy.init()
    return serve_node(LatencyPeer(args.feedbacks, args.feedback_period_s))


def serve_node(node: Node) -> int:
    """Spin a stand-in peer until SIGINT/SIGTERM; print READY first, for the parent waiting on it."""
    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    print("READY", flush=True)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown(timeout_sec=0.5)
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
