"""A SiLA server never shares its port: a second one on a taken address is refused by name.

gRPC binds with SO_REUSEPORT, so without our check two stacks given the same ports both start and
the kernel splits clients between them. Real sila2 servers and a real client over gRPC here.
"""

from __future__ import annotations

import socket
import threading

import pytest
from sila2.client import SilaClient
from sila2.server import SilaServer

from sila_labware.servers import serving
from sila_labware.servers.serving import PortInUseError, port_is_free, start_sila_server, stop_sila_server
from tests.helpers.sila_stack import free_port_base


def bare_server(name: str) -> SilaServer:
    return SilaServer(
        server_name=name,
        server_type="PortTest",
        server_version="0.1",
        server_description="a server with only the SiLAService feature",
        server_vendor_url="https://example.org",
    )


@pytest.fixture(autouse=True)
def short_release_wait(monkeypatch: pytest.MonkeyPatch) -> None:
    """A taken port stays taken here: no need to watch it for the full wait."""
    monkeypatch.setattr(serving, "PORT_RELEASE_WAIT_S", 0.3)


def test_a_second_server_on_a_taken_port_is_refused_and_the_first_keeps_serving():
    port = free_port_base(1)
    first, second = bare_server("First"), bare_server("Second")
    start_sila_server(first, "127.0.0.1", port, authority=None, discovery=False)
    try:
        assert not port_is_free("127.0.0.1", port)
        with pytest.raises(PortInUseError, match=f"127.0.0.1:{port} is already in use"):
            start_sila_server(second, "127.0.0.1", port, authority=None, discovery=False)
        assert not second.running
        client = SilaClient("127.0.0.1", port, insecure=True)
        assert client.SiLAService.ServerName.get() == "First"
    finally:
        first.stop(grace_period=0.2)
    # the client's connection may linger in TIME_WAIT; the port counts as free once nobody listens
    assert port_is_free("127.0.0.1", port)


def test_a_port_held_by_any_listener_is_refused():
    port = free_port_base(1)
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", port))
        listener.listen()
        server = bare_server("Late")
        with pytest.raises(PortInUseError, match=f"127.0.0.1:{port}"):
            start_sila_server(server, "127.0.0.1", port, authority=None, discovery=False)
        assert not server.running


def _zeroconf_threads() -> int:
    return sum(1 for thread in threading.enumerate() if thread.name.endswith("(_run_loop)"))


def test_a_stopped_server_leaves_no_zeroconf_thread_behind():
    """sila2 opens a Zeroconf per server, announcing or not, and never closes it; a campaign worker
    starts three servers a trial."""
    before = _zeroconf_threads()
    for name in ("One", "Two", "Three"):
        server = bare_server(name)
        port = free_port_base(1)
        start_sila_server(server, "127.0.0.1", port, authority=None, discovery=False)
        assert SilaClient("127.0.0.1", port, insecure=True).SiLAService.ServerName.get() == name
        stop_sila_server(server)
        assert not server.running
    assert _zeroconf_threads() == before
