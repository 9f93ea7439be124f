"""Shared set-up of the SiLA tests: the whole stack (real sim node, sequencer, bridge, servers)."""

from __future__ import annotations

from pathlib import Path

from sila2.client import SilaClient

from sila_labware.deployment.stack import Deployment, DeploymentOptions, ServedServer
from sila_labware.testing.ports import free_port_base

REPOSITORY = Path(__file__).resolve().parents[2]
DEFAULT_WORLD = REPOSITORY / "lab_description" / "worlds" / "default.yaml"


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
