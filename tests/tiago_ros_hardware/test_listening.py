"""The adapter's short-lived subscriptions (camera, laser) never end an executor thread.

Why: rclpy 7.1 builds an executor's wait set by marking each waitable in use, then adding it; a
subscription's QoS event handler destroyed between the two raises "cannot use Destroyable because
destruction was requested" in the executor's thread, and spin() ends: no reading reached the
adapter again (a loaded CI run, every later test of the module failing). Real rclpy here: the
adapter on a node that a multi-threaded executor spins on other threads, subscribing and
unsubscribing as a skill reading the laser does, with the interpreter switching threads every
microsecond so that the window opens often. With rclpy's default event handlers on those
subscriptions, the same loop ended the executor within 60 rounds when this test was written.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Iterator

import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node

from robot_port.tiago_interfaces import LASER
from tiago_ros_hardware.hardware import LaserScanMsg, RosHardware

ROUNDS = 1500


@pytest.fixture
def spun_node() -> Iterator[tuple[Node, list[BaseException]]]:
    context = Context()
    rclpy.init(context=context)
    node = rclpy.create_node("listening_probe", context=context)
    executor = MultiThreadedExecutor(num_threads=4, context=context)
    executor.add_node(node)
    ended: list[BaseException] = []

    def spin() -> None:
        try:
            executor.spin()
        except BaseException as error:  # noqa: BLE001 - what ended the executor is the finding
            ended.append(error)

    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    try:
        yield node, ended
    finally:
        executor.shutdown()
        spinner.join(timeout=10.0)
        node.destroy_node()
        rclpy.shutdown(context=context)


def test_subscribing_and_unsubscribing_leaves_the_executor_spinning(
    spun_node: tuple[Node, list[BaseException]],
) -> None:
    node, ended = spun_node
    hardware = RosHardware(node)  # its action clients are the waitables the wait set walks
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    try:
        for _ in range(ROUNDS):
            with hardware._listening((LASER, LaserScanMsg, hardware.scans)):
                pass
            if ended:
                break
    finally:
        sys.setswitchinterval(interval)
    assert not ended, f"the executor ended: {ended[0]!r}"
