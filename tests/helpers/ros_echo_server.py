"""A small real ROS 2 peer for the bridge tests, run as a separate process.

Serves /navigate_to_poi (NavigateToPoi): drives a pretend base for `--goal-seconds`, sending
feedback at 20 Hz; POI "nowhere" aborts with UNKNOWN_POI; cancel is honoured. Serves
/describe_workcell with two stations. Publishes RobotState on /robot_state at 10 Hz, whose
`detail` counts the goals finished so far, and an empty /labware_inventory (nothing aboard, no
plate named). Prints "READY" once everything is created.

A misbehaving robot side, for the bridge's own tests: `--accept-delay-s S` answers every goal
request only after S seconds (a slow or overloaded action server), and `--goal-log FILE` appends
one line per goal event ("accepted POI", "canceled POI", "succeeded POI", "aborted POI"), so a
test can see what the robot side really did.
"""

from __future__ import annotations

import argparse
import sys
import threading
import time
from pathlib import Path

import rclpy
from labware_interfaces.action import NavigateToPoi
from labware_interfaces.msg import ErrorCodes, LabwareInventory, RobotState, StationInfo
from labware_interfaces.srv import DescribeWorkcell
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from ros_bridge.latency_peer import serve_node
from ros_bridge.topics import INVENTORY_QOS


class EchoRobot(Node):
    """Pretend robot: one action, one service, one state topic."""

    def __init__(
        self, goal_seconds: float, accept_delay_s: float = 0.0, goal_log: Path | None = None
    ) -> None:
        super().__init__("bridge_test_echo_robot")
        self._goal_seconds = goal_seconds
        self._accept_delay_s = accept_delay_s
        self._goal_log = goal_log
        self._finished_goals = 0
        self._current_poi = ""
        self._lock = threading.Lock()
        group = ReentrantCallbackGroup()
        self._action_server = ActionServer(
            self,
            NavigateToPoi,
            "/navigate_to_poi",
            execute_callback=self._execute,
            goal_callback=self._accept,
            cancel_callback=lambda _handle: CancelResponse.ACCEPT,
            callback_group=group,
        )
        self._service = self.create_service(
            DescribeWorkcell, "/describe_workcell", self._describe, callback_group=group
        )
        self._state_publisher = self.create_publisher(RobotState, "/robot_state", 1)
        self._timer = self.create_timer(0.1, self._publish_state, callback_group=group)
        self.create_publisher(LabwareInventory, "/labware_inventory", INVENTORY_QOS).publish(
            LabwareInventory(revision=1)
        )

    def _accept(self, goal: NavigateToPoi.Goal) -> GoalResponse:
        time.sleep(self._accept_delay_s)
        self._log("accepted", goal.poi)
        return GoalResponse.ACCEPT

    def _log(self, event: str, poi: str) -> None:
        if self._goal_log is not None:
            with self._lock, self._goal_log.open("a") as log:
                log.write(f"{event} {poi}\n")

    def _describe(self, _request: DescribeWorkcell.Request, response: DescribeWorkcell.Response):
        response.stations = [
            StationInfo(name="reader", sub_positions=1, poi="reader_poi"),
            StationInfo(name="rack", sub_positions=4, poi="rack_poi"),
        ]
        response.hotel_slots = 2
        response.pois = ["reader_poi", "rack_poi", "dock_approach"]
        response.dock_poi = "dock_approach"
        response.nest_sensors = response.hotel_sensors = response.label_readers = True
        return response

    def _publish_state(self) -> None:
        with self._lock:
            message = RobotState(
                state=RobotState.STATE_IDLE,
                detail=f"finished {self._finished_goals}",
                current_poi=self._current_poi,
            )
        message.stamp = self.get_clock().now().to_msg()
        self._state_publisher.publish(message)

    def _execute(self, goal_handle) -> NavigateToPoi.Result:
        poi = goal_handle.request.poi
        result = NavigateToPoi.Result()
        if poi == "nowhere":
            self._log("aborted", poi)
            goal_handle.abort()
            result.success, result.error_code = False, ErrorCodes.UNKNOWN_POI
            result.message = f"no point of interest named {poi!r}"
            return result
        started = time.monotonic()
        while True:
            elapsed = time.monotonic() - started
            if goal_handle.is_cancel_requested:
                self._log("canceled", poi)
                goal_handle.canceled()
                result.success, result.error_code = False, ErrorCodes.CANCELED
                result.message = f"cancelled after {elapsed:.2f} s"
                return result
            if elapsed >= self._goal_seconds:
                break
            feedback = NavigateToPoi.Feedback(
                progress=elapsed / self._goal_seconds,
                phase="driving",
                remaining_time_s=self._goal_seconds - elapsed,
            )
            goal_handle.publish_feedback(feedback)
            time.sleep(0.05)
        self._log("succeeded", poi)
        goal_handle.succeed()
        with self._lock:
            self._finished_goals += 1
            self._current_poi = poi
        result.success, result.message = True, f"arrived at {poi}"
        return result


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--goal-seconds", type=float, default=1.0)
    parser.add_argument("--accept-delay-s", type=float, default=0.0)
    parser.add_argument("--goal-log", type=Path, default=None)
    args = parser.parse_args()
    rclpy.init()
    return serve_node(EchoRobot(args.goal_seconds, args.accept_delay_s, args.goal_log))


if __name__ == "__main__":
    sys.exit(main())
