"""Fixtures of the device-logic tests: a RobotLink to the echo peer over real DDS."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime
from tests.helpers.echo_peer import running_echo_peer


@pytest.fixture(scope="module")
def link() -> Iterator[RobotLink]:
    """Goals of the peer take 3 s: long enough to time out or cancel one mid-way."""
    with running_echo_peer(3.0):
        runtime = RosRuntime("controller_test").start()
        try:
            yield RobotLink(runtime)
        finally:
            runtime.stop()
