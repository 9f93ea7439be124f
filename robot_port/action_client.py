"""An rclpy action client that may be called from any thread while executor threads spin it.

Why: rclpy 7.1 (ROS 2 Jazzy, the version this project pins) sends a goal request first and records
its sequence number after. An executor thread that takes the server's answer in between finds no
request for it, drops it with "Ignoring unexpected goal response. There may be more than one action
server", and the goal's future never completes: ros2/rclpy issue 1123, fixed upstream after this
release. Seen here under load: a named motion sent through the ROS adapter from a skill's thread
"did not end" with the warning and one play_motion2 server. The same holds for cancel and result
requests. One lock per client puts a request's bookkeeping before the handling of any answer.

Used wherever a goal is sent from a thread other than the one spinning the client: the ROS adapter
(skills' threads), the sequencer and the simulator's play_motion2 stand-in (multi-threaded
executors).
"""

from __future__ import annotations

import threading
from typing import Any

from rclpy.action import ActionClient


class ThreadSafeActionClient(ActionClient):
    """rclpy's ActionClient with its requests and the handling of their answers serialised."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._bookkeeping = threading.RLock()  # re-entrant: a done callback may send the next request
        super().__init__(*args, **kwargs)

    def send_goal_async(self, *args: Any, **kwargs: Any) -> Any:
        with self._bookkeeping:
            return super().send_goal_async(*args, **kwargs)

    def _cancel_goal_async(self, goal_handle: Any) -> Any:
        with self._bookkeeping:
            return super()._cancel_goal_async(goal_handle)

    def _get_result_async(self, goal_handle: Any) -> Any:
        with self._bookkeeping:
            return super()._get_result_async(goal_handle)

    async def execute(self, taken_data: Any) -> None:
        with self._bookkeeping:  # the base class awaits nothing but synchronous feedback callbacks
            await super().execute(taken_data)
