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
from collections.abc import Iterator

import pytest
from rclpy.node import Node

from robot_port.tiago_interfaces import LASER
from tests.helpers.spun_node import spun_node
from tiago_ros_hardware.hardware import LaserScanMsg, RosHardware

ROUNDS = 1500


@pytest.fixture
def spun() -> Iterator[tuple[Node, list[BaseException]]]:
    with spun_node("listening_probe", threads=4) as node_and_end:
        yield node_and_end


def test_subscribing_and_unsubscribing_leaves_the_executor_spinning(
    spun: tuple[Node, list[BaseException]],
) -> None:
    node, ended = spun
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
