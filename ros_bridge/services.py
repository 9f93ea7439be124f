"""Call a ROS 2 service from any thread with a timeout.

Threads: the rclpy client is created and called on the ROS thread of a `RosRuntime`; the
caller waits on a `concurrent.futures.Future` with a timeout and never spins.
"""

from __future__ import annotations

import concurrent.futures
import time
from typing import Any

from ros_bridge.errors import BridgeError, BridgeTimeout, ServerUnavailable
from ros_bridge.runtime import RosRuntime


class ServiceCaller:
    """A client of one service (`service_type` at `service_name`), usable from any thread."""

    def __init__(self, runtime: RosRuntime, service_type: type, service_name: str) -> None:
        self._runtime = runtime
        self.service_type = service_type
        self.service_name = service_name
        self._client = runtime.call(lambda: runtime.node.create_client(service_type, service_name))

    def is_ready(self) -> bool:
        return bool(self._runtime.call(self._client.service_is_ready))

    def wait_for_service(self, timeout_s: float = 10.0) -> None:
        """Return once the service is discovered; raise ServerUnavailable naming it otherwise."""
        deadline = time.monotonic() + timeout_s
        while not self.is_ready():
            if time.monotonic() >= deadline:
                raise ServerUnavailable(
                    f"service {self.service_name} ({self.service_type.__name__}) not available after "
                    f"{timeout_s:.1f} s; is the robot side running in this ROS domain?"
                )
            time.sleep(0.05)

    def call(self, request: Any, timeout_s: float = 5.0) -> Any:
        """Send `request` and return the response; BridgeTimeout if none comes in time."""
        answer: concurrent.futures.Future[Any] = concurrent.futures.Future()

        def call_on_ros_thread() -> Any:
            ros_future = self._client.call_async(request)
            ros_future.add_done_callback(lambda done: _copy(done, answer))
            return ros_future

        ros_future = self._runtime.call(call_on_ros_thread, timeout_s)
        try:
            return answer.result(timeout=timeout_s)
        except concurrent.futures.TimeoutError as error:
            self._runtime.submit(lambda: self._client.remove_pending_request(ros_future))
            raise BridgeTimeout(
                f"service {self.service_name}: no response within {timeout_s:.1f} s"
            ) from error

    def destroy(self) -> None:
        if self._runtime.running:
            self._runtime.call(lambda: self._runtime.node.destroy_client(self._client))


def _copy(ros_future: Any, target: concurrent.futures.Future) -> None:
    error = ros_future.exception()
    if error is not None:
        target.set_exception(BridgeError(f"service call failed: {error}"))
    else:
        target.set_result(ros_future.result())
