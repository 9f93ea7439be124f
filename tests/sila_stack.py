"""Shared set-up of the SiLA tests: the whole stack (real sim node, sequencer, bridge, servers)."""

from __future__ import annotations

import socket
from pathlib import Path

from sila2.client import SilaClient

from sila_labware.deployment import Deployment, DeploymentOptions, ServedServer

REPOSITORY = Path(__file__).resolve().parent.parent
DEFAULT_WORLD = REPOSITORY / "tiago_sim" / "worlds" / "default.yaml"


def free_port_base(count: int) -> int:
    """A port with `count` free ports from it on (checked by binding them on 127.0.0.1)."""
    for _attempt in range(50):
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            base = probe.getsockname()[1]
        if base + count > 65535:
            continue
        sockets = []
        try:
            for port in range(base, base + count):
                held = socket.socket()
                sockets.append(held)
                held.bind(("127.0.0.1", port))
            return base
        except OSError:
            continue
        finally:
            for held in sockets:
                held.close()
    raise RuntimeError("no block of free ports found")


def start_stack(
    tmp_dir: Path, *, insecure: bool = False, discovery: bool = False, world: Path = DEFAULT_WORLD
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
        )
    )
    deployment.start()
    return deployment


def client_for(deployment: Deployment, served: ServedServer) -> SilaClient:
    if deployment.ca_file is None:
        return SilaClient(served.host, served.port, insecure=True)
    return SilaClient(served.host, served.port, root_certs=deployment.ca_file.read_bytes())
