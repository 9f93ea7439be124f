"""Shared set-up of the SiLA tests: the whole stack (real sim node, sequencer, bridge, servers)."""

from __future__ import annotations

import socket
from collections.abc import Iterator
from pathlib import Path

from sila2.client import SilaClient

from sila_labware.deployment.stack import Deployment, DeploymentOptions, ServedServer
from sila_labware.servers.serving import port_is_free

REPOSITORY = Path(__file__).resolve().parents[2]
DEFAULT_WORLD = REPOSITORY / "tiago_sim" / "worlds" / "default.yaml"


def free_port_base(count: int, candidates: range | None = None) -> int:
    """A port with ``count`` free ports on 127.0.0.1 from it on: the first such in ``candidates``,
    else one the kernel hands out as ephemeral (so parallel runs rarely pick the same)."""
    for base in candidates if candidates is not None else _ephemeral_ports(50):
        ports = range(base, base + count)
        if ports.stop <= 65536 and all(port_is_free("127.0.0.1", port) for port in ports):
            return base
    raise RuntimeError(f"no block of {count} free ports found")


def _ephemeral_ports(count: int) -> Iterator[int]:
    for _attempt in range(count):
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            port = probe.getsockname()[1]
        yield port


def start_stack(
    tmp_dir: Path,
    *,
    insecure: bool = False,
    discovery: bool = False,
    world: Path = DEFAULT_WORLD,
    lab_name: str = "",
    pace: float | None = None,
) -> Deployment:
    deployment = Deployment(
        DeploymentOptions(
            world=world,
            host="127.0.0.1",
            port_base=free_port_base(4),
            insecure=insecure,
            ca_file=tmp_dir / "ca.pem",
            discovery=discovery,
            ready_timeout_s=120.0,
            log_dir=tmp_dir / "logs",
            lab_name=lab_name,
            pace=pace,
        )
    )
    deployment.start()
    return deployment


def client_for(deployment: Deployment, served: ServedServer) -> SilaClient:
    if deployment.ca_file is None:
        return SilaClient(served.host, served.port, insecure=True)
    return SilaClient(served.host, served.port, root_certs=deployment.ca_file.read_bytes())
