"""A goal sent from one thread while executor threads spin the client is answered, however late the
sending thread records its request (rclpy's race, robot_port.action_client).

Real rclpy over DDS: an action server and the client in one node, spun by a multi-threaded executor
on another thread. The client's handle is wrapped so that the sending thread pauses right after a
request went out, before rclpy records it, as a loaded machine's scheduler may pause it; a plain
rclpy ActionClient then drops the server's answer and the goal's future never completes.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest
from control_msgs.action import FollowJointTrajectory
from rclpy.action import ActionServer
from rclpy.node import Node

from robot_port.action_client import ThreadSafeActionClient
from tests.helpers.spun_node import spun_node

ACTION = "/thread_safe_action_client_probe"
PAUSE_S = 0.3


class PausedAfterSending:
    """An rcl action client handle whose requests leave, then the sending thread pauses."""

    def __init__(self, handle: Any) -> None:
        self._handle = handle

    def _paused(self, send: Any, request: Any) -> int:
        sequence_number = send(request)
        time.sleep(PAUSE_S)
        return sequence_number

    def send_goal_request(self, request: Any) -> int:
        return self._paused(self._handle.send_goal_request, request)

    def send_result_request(self, request: Any) -> int:
        return self._paused(self._handle.send_result_request, request)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._handle, name)


def succeed(handle: Any) -> Any:
    handle.succeed()
    return FollowJointTrajectory.Result(error_string="done")


@pytest.fixture
def node() -> Iterator[Node]:
    with spun_node("thread_safe_action_client_probe") as (node, _ended):
        ActionServer(node, FollowJointTrajectory, ACTION, execute_callback=succeed)  # torn down with it
        yield node


def test_a_goal_sent_from_another_thread_gets_its_answer_and_result(node: Node) -> None:
    client = ThreadSafeActionClient(node, FollowJointTrajectory, ACTION)
    assert client.wait_for_server(timeout_sec=10.0)
    client._client_handle = PausedAfterSending(client._client_handle)
    answered = threading.Event()
    sent = client.send_goal_async(FollowJointTrajectory.Goal())
    sent.add_done_callback(lambda _future: answered.set())
    assert answered.wait(10.0), "the goal's answer was dropped"
    assert sent.result().accepted
    finished = threading.Event()
    result = sent.result().get_result_async()
    result.add_done_callback(lambda _future: finished.set())
    assert finished.wait(10.0), "the result's answer was dropped"
    assert result.result().result.error_string == "done"
    client.destroy()
