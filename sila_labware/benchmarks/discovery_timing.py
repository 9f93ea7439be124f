"""How long `sila-labware serve` takes until every one of its SiLA servers is discoverable (mDNS).

The clock starts just before the `serve` process is launched and stops when zeroconf has resolved
a `_sila._tcp` service for every port `serve` printed. A plain zeroconf browser is used (not a
SiLA client), so what is measured is the announcement, not a TLS handshake.

Threads: zeroconf calls the listener on its own thread; it only records times under a lock.
"""

from __future__ import annotations

import logging
import os
import re
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from zeroconf import ServiceBrowser, ServiceListener, Zeroconf

from sila_labware.benchmarks.child_lines import ChildLines

logger = logging.getLogger(__name__)

SILA_SERVICE_TYPE = "_sila._tcp.local."
SERVER_LINE = re.compile(r"^(robot|station)\s+.+\s(\S+):(\d+)$")


@dataclass(frozen=True)
class DiscoveryTiming:
    """Seconds from launching `serve` to: its server list printed, every server discoverable."""

    servers: int
    printed_s: float
    discoverable_s: float


class _PortListener(ServiceListener):
    """Records when a SiLA service on each port was first resolved."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.first_seen: dict[int, float] = {}

    def _resolve(self, zeroconf: Zeroconf, service_type: str, name: str) -> None:
        info = zeroconf.get_service_info(service_type, name, timeout=2000)
        if info is None or info.port is None:
            return
        with self.lock:
            self.first_seen.setdefault(int(info.port), time.monotonic())

    def add_service(self, zc: Zeroconf, type_: str, name: str) -> None:
        self._resolve(zc, type_, name)

    def update_service(self, zc: Zeroconf, type_: str, name: str) -> None:
        self._resolve(zc, type_, name)

    def remove_service(self, zc: Zeroconf, type_: str, name: str) -> None:
        pass


def time_serve_until_discoverable(
    world: Path, port_base: int, ca_file: Path, timeout_s: float = 180.0
) -> DiscoveryTiming:
    """Launch `serve` (TLS, discovery on), wait until all its servers are discoverable, stop it.
    RuntimeError (ChildSilent, a TimeoutError, if `serve` says nothing) after `timeout_s`."""
    zeroconf = Zeroconf()
    listener = _PortListener()
    browser = ServiceBrowser(zeroconf, SILA_SERVICE_TYPE, listener)
    command = [sys.executable, "-m", "sila_labware.cli", "serve", "--world", str(world)]
    command += ["--port-base", str(port_base), "--ca-file", str(ca_file)]
    started = time.monotonic()
    serve = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=dict(os.environ)
    )
    try:
        ports, printed_s = _read_server_ports(serve, started, timeout_s)
        deadline = started + timeout_s
        while True:
            with listener.lock:
                seen = {port: listener.first_seen[port] for port in ports if port in listener.first_seen}
            if len(seen) == len(ports):
                return DiscoveryTiming(len(ports), printed_s, max(seen.values()) - started)
            if time.monotonic() > deadline or serve.poll() is not None:
                raise RuntimeError(f"servers on ports {sorted(set(ports) - set(seen))} never discoverable")
            time.sleep(0.01)
    finally:
        browser.cancel()
        zeroconf.close()
        _stop(serve)


def _read_server_ports(
    serve: subprocess.Popen[str], started: float, timeout_s: float
) -> tuple[list[int], float]:
    """The ports `serve` lists, and when it finished listing them (the "serving" line)."""
    assert serve.stdout is not None
    lines = ChildLines(serve.stdout, "serve")
    ports: list[int] = []
    while (line := lines.next_line(started + timeout_s - time.monotonic())) is not None:
        match = SERVER_LINE.match(line.strip())
        if match:
            ports.append(int(match.group(3)))
        if line.startswith("serving"):
            return ports, time.monotonic() - started
    raise RuntimeError(f"serve did not report its servers (exit code {serve.poll()})")


def _stop(serve: subprocess.Popen[str]) -> None:
    if serve.poll() is None:
        serve.send_signal(signal.SIGINT)
        try:
            serve.wait(timeout=10.0)
        except subprocess.TimeoutExpired:
            serve.kill()
            serve.wait(timeout=10.0)
    if serve.stdout is not None:
        serve.stdout.close()
