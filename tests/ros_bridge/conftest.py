"""Fixtures of the bridge tests: the echo peer in its own process (real DDS, no simulation).

A test module sets `ECHO_GOAL_SECONDS` to choose how long the peer's goals take (default 1 s).
"""

from __future__ import annotations

import subprocess
from collections.abc import Iterator

import pytest

from tests.helpers.echo_peer import running_echo_peer


@pytest.fixture(scope="module")
def echo_server(request: pytest.FixtureRequest) -> Iterator[subprocess.Popen]:
    with running_echo_peer(getattr(request.module, "ECHO_GOAL_SECONDS", 1.0)) as process:
        yield process
