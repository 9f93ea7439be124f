"""Every blocking sila2 call of the client is bounded: a server that takes the connection but never
answers makes the client raise ServerUnreachable, not hang (sila2 sets no gRPC deadline)."""

from __future__ import annotations

import socket
import time

import pytest
from sila2.client import SilaClient

from sila_labware.client.bounded import bounded
from sila_labware.client.errors import ServerUnreachable


def test_a_server_that_never_answers_is_unreachable_after_the_bound() -> None:
    with socket.socket() as mute_server:  # accepts TCP connections, never speaks HTTP/2
        mute_server.bind(("127.0.0.1", 0))
        mute_server.listen()
        host, port = mute_server.getsockname()
        started = time.monotonic()
        with pytest.raises(ServerUnreachable, match=r"127.0.0.1:\d+: no answer within 1 s"):
            bounded(lambda: SilaClient(host, port, insecure=True), 1.0, f"{host}:{port}")
        assert time.monotonic() - started < 3.0


def test_a_bounded_call_returns_its_value_or_raises_its_error() -> None:
    assert bounded(lambda: 42, 1.0, "answer") == 42
    with pytest.raises(ZeroDivisionError):
        bounded(lambda: 1 / 0, 1.0, "division")
