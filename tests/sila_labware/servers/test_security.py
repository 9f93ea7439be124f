"""Security of `sila-labware serve`, as a user starts it (a real subprocess, real gRPC and TLS).

- TLS unless --insecure; --insecure logs a warning on stderr at start, TLS runs do not;
- only a client trusting the deployment's CA gets an answer: sila2's SilaClient without root
  certificates, with another CA, or in plain text fails, and so does a raw gRPC channel (plain or
  with the wrong CA) - while the same raw call with the right CA succeeds, so the failures are TLS;
- the servers bind where --host says, and nowhere else: by default 127.0.0.1 only; with
  --host 127.0.0.2 only that (checked in the kernel's socket table and by connecting to the other
  local addresses: loopback ones and this machine's network address).
"""

from __future__ import annotations

import ipaddress
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import grpc
import pytest
from sila2.client import SilaClient

from sila_labware.servers.tls import CertificateAuthority
from tests.helpers.sila_stack import free_port_base

CLI = [sys.executable, "-m", "sila_labware.cli"]
CHOSEN_HOST = "127.0.0.2"  # a loopback address other than the default, so the test needs no network
INSECURE_WARNING = "serving WITHOUT encryption (--insecure)"
SERVER_NAME_METHOD = "/sila2.org.silastandard.core.silaservice.v1.SiLAService/Get_ServerName"


@dataclass
class Served:
    process: subprocess.Popen
    host: str
    port: int
    ca_file: Path
    stdout_lines: list[str]

    def stderr_text(self) -> str:
        """Everything the process wrote to stderr (call after it stopped)."""
        assert self.process.stderr is not None
        return self.process.stderr.read()


def serve(tmp_path: Path, *extra: str) -> Served:
    """Start `sila-labware serve` and wait until it says it serves."""
    port = free_port_base(4)
    ca_file = tmp_path / "ca.pem"
    arguments = ["serve", "--port-base", str(port), "--ca-file", str(ca_file), "--no-discovery", *extra]
    process = subprocess.Popen([*CLI, *arguments], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines: list[str] = []
    assert process.stdout is not None
    while not lines or lines[-1] != "serving; Ctrl-C stops":
        line = process.stdout.readline()
        if not line:
            stop(process)
            pytest.fail(f"serve ended early: {process.stderr.read() if process.stderr else ''}")
        lines.append(line.rstrip("\n"))
    host = extra[extra.index("--host") + 1] if "--host" in extra else "127.0.0.1"
    return Served(process, host, port, ca_file, lines)


def stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


@pytest.fixture(scope="module")
def tls_serve(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Served]:
    served = serve(tmp_path_factory.mktemp("security"), "--host", CHOSEN_HOST)  # default: TLS
    yield served
    stop(served.process)


def server_name(client: SilaClient) -> str:
    return client.SiLAService.ServerName.get()


def raw_server_name(channel: grpc.Channel) -> bytes:
    """SiLAService.Get_ServerName as raw bytes over a bare gRPC channel (no SiLA library)."""
    call = channel.unary_unary(SERVER_NAME_METHOD)
    return call(b"", timeout=5.0)


def test_insecure_serve_warns_at_start(tmp_path: Path) -> None:
    served = serve(tmp_path, "--insecure")
    try:
        # Plain text really works in this mode (what the warning is about) ...
        client = SilaClient("127.0.0.1", served.port, insecure=True)
        assert server_name(client) == "TIAGo Labware Robot (default lab)"
        assert not served.ca_file.exists(), "no CA is written for a plain-text deployment"
        assert_bound_only_to(served, "127.0.0.1")  # the default --host
    finally:
        stop(served.process)
    assert served.process.returncode == 0
    # ... and the user was told so on stderr, once, at start.
    assert served.stderr_text().count(INSECURE_WARNING) == 1


def test_tls_serve_answers_clients_that_trust_its_ca(tls_serve: Served) -> None:
    assert any(line.startswith("CA file for clients:") for line in tls_serve.stdout_lines)
    root_certs = tls_serve.ca_file.read_bytes()
    client = SilaClient(tls_serve.host, tls_serve.port, root_certs=root_certs)
    assert server_name(client) == "TIAGo Labware Robot (default lab)"
    station = SilaClient(tls_serve.host, tls_serve.port + 1, root_certs=root_certs)
    assert server_name(station).startswith("Station")
    channel = grpc.secure_channel(
        f"{tls_serve.host}:{tls_serve.port}", grpc.ssl_channel_credentials(root_certs)
    )
    with channel:
        assert b"TIAGo Labware Robot (default lab)" in raw_server_name(channel)


@pytest.mark.parametrize("how", ["system roots only", "another CA", "plain text"])
def test_sila_client_without_the_ca_cannot_connect(tls_serve: Served, how: str) -> None:
    started = time.monotonic()
    with pytest.raises(Exception) as caught:  # noqa: PT011 - the library raises what gRPC raises
        if how == "system roots only":
            client = SilaClient(tls_serve.host, tls_serve.port)
        elif how == "another CA":
            client = SilaClient(
                tls_serve.host, tls_serve.port, root_certs=CertificateAuthority().certificate_pem
            )
        else:
            client = SilaClient(tls_serve.host, tls_serve.port, insecure=True)
        server_name(client)
    assert "TIAGo" not in str(caught.value)
    assert time.monotonic() - started < 30.0, "a refused client must fail, not hang"


@pytest.mark.parametrize("how", ["plain text", "another CA"])
def test_raw_grpc_without_the_ca_cannot_connect(tls_serve: Served, how: str) -> None:
    target = f"{tls_serve.host}:{tls_serve.port}"
    if how == "plain text":
        channel = grpc.insecure_channel(target)
    else:
        wrong_ca = CertificateAuthority().certificate_pem
        channel = grpc.secure_channel(target, grpc.ssl_channel_credentials(wrong_ca))
    with channel, pytest.raises(grpc.RpcError) as caught:
        raw_server_name(channel)
    assert caught.value.code() == grpc.StatusCode.UNAVAILABLE, caught.value


def local_addresses() -> list[str]:
    """Two loopback addresses and this machine's own address on its network, if it has one."""
    addresses = {"127.0.0.1", CHOSEN_HOST}
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        try:
            probe.connect(("192.0.2.1", 9))  # no packet is sent: this only picks the outgoing interface
            addresses.add(probe.getsockname()[0])
        except OSError:
            pass
    return sorted(addresses)


def kernel_address(hex_address: str) -> str:
    """An address as /proc/net/tcp{,6} prints it (32-bit words in host order, little-endian here);
    an IPv4-mapped IPv6 address comes back as plain IPv4."""
    raw = b"".join(bytes.fromhex(hex_address[i : i + 8])[::-1] for i in range(0, len(hex_address), 8))
    address = ipaddress.ip_address(raw)
    mapped = getattr(address, "ipv4_mapped", None)
    return str(mapped or address)


def listening_addresses(port: int) -> set[str]:
    """Local addresses with a listening TCP socket on `port`, from the kernel's socket tables."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            address, port_hex = fields[1].rsplit(":", 1)
            if int(port_hex, 16) == port and fields[3] == "0A":  # 0A: LISTEN
                found.add(kernel_address(address))
    return found


def assert_bound_only_to(served: Served, host: str) -> None:
    for port in range(served.port, served.port + 3):  # the robot and both stations
        assert listening_addresses(port) == {host}, f"only {host} listens on {port}"
        for address in local_addresses():
            if address == host:
                socket.create_connection((address, port), timeout=3.0).close()
            else:
                with pytest.raises(ConnectionRefusedError):
                    socket.create_connection((address, port), timeout=3.0).close()


def test_servers_bind_only_where_host_says(tls_serve: Served) -> None:
    assert tls_serve.host == CHOSEN_HOST
    assert_bound_only_to(tls_serve, CHOSEN_HOST)
