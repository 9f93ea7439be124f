"""Start a SiLA server on a port that no other process listens on, with or without TLS.

Why a port check of our own: the sila2 library builds its gRPC server with gRPC's defaults, and
gRPC binds with SO_REUSEPORT. A second `sila-labware serve` or `bench` given the same ports then
starts without complaint, and the kernel splits client connections between the two stacks: a
client's calls reach whichever robot the kernel picks. A plain bind (no SO_REUSEPORT) is refused
while anyone listens on the port, so probing with one turns that into a clear error.
"""

from __future__ import annotations

import logging
import socket
import time

from sila2.server import SilaServer

from sila_labware.servers.tls import CertificateAuthority

log = logging.getLogger(__name__)

PORT_RELEASE_WAIT_S = 3.0
"""How long a taken port is watched before giving up: a server this process stopped a moment ago
(the previous bench trial's) closes its listener only when its last command has wound down."""


class PortInUseError(RuntimeError):
    """The address to serve on is taken (by another server, or by anything listening there)."""


def port_is_free(host: str, port: int) -> bool:
    """Whether nothing listens on host:port (a bind without SO_REUSEPORT succeeds).

    SO_REUSEADDR is set so that connections of a server stopped a moment ago, still in TIME_WAIT,
    do not count: Linux refuses that bind only while a socket listens on the port.
    """
    family, kind, protocol, _name, address = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0]
    with socket.socket(family, kind, protocol) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(address)
        except OSError:
            return False
    return True


def start_sila_server(
    server: SilaServer,
    host: str,
    port: int,
    *,
    authority: CertificateAuthority | None,
    discovery: bool,
) -> None:
    """Start ``server`` on host:port; TLS with a certificate from ``authority``, none without one.

    Raises PortInUseError, naming the address, when something still listens there after
    ``PORT_RELEASE_WAIT_S``.
    """
    deadline = time.monotonic() + PORT_RELEASE_WAIT_S
    while not port_is_free(host, port):
        if time.monotonic() >= deadline:
            raise PortInUseError(
                f"{host}:{port} is already in use (another sila-labware serve or bench?); "
                "give this one other ports (--port-base or --port)"
            )
        time.sleep(0.05)
    if authority is None:
        server.start_insecure(host, port, enable_discovery=discovery)
        return
    credentials = authority.issue_server_credentials(server.server_uuid, server.server_name, host)
    server.start(
        host,
        port,
        private_key=credentials.private_key_pem,
        cert_chain=credentials.certificate_pem,
        enable_discovery=discovery,
        ca_for_discovery=authority.certificate_pem,
    )


def stop_sila_server(server: SilaServer, grace_period: float = 0.2) -> None:
    """Stop ``server`` (if it runs) and close the zeroconf instance sila2 gave it.

    Why: sila2 opens a Zeroconf (a thread and multicast sockets) in every server's constructor,
    whether or not the server announces itself, and never closes it. A process that starts
    servers again and again (a campaign worker runs three per trial) kept three more threads per
    trial: 180 after 60 trials of one worker.
    """
    try:
        if server.running:
            server.stop(grace_period=grace_period)
    finally:
        broadcaster = getattr(server, "_SilaServer__service_broadcaster", None)
        zeroconf = getattr(broadcaster, "zc", None)
        if zeroconf is None:
            log.debug("no zeroconf found on %s (another sila2 version?)", server.server_name)
        else:
            zeroconf.close()
