"""A `LabwareTransferClient` for a running `Deployment`: its servers' addresses and its CA.

Why here and not in the client: the client knows only addresses and certificates, so that it runs
against any `serve`; this is the shortcut for code that started the deployment itself (the demo,
the benchmarks, tests).

Threads: the caller's.
"""

from __future__ import annotations

from sila_labware.client import LabwareTransferClient
from sila_labware.client.steps import DEFAULT_STEP_TIMEOUT_S
from sila_labware.deployment.stack import Deployment


def transfer_client(
    deployment: Deployment, step_timeout_s: float = DEFAULT_STEP_TIMEOUT_S
) -> LabwareTransferClient:
    """Connected to the deployment's robot server and every station server; close it after use."""
    robot = deployment.robot_server()
    stations = [(served.host, served.port) for served in deployment.servers if served.role == "station"]
    if deployment.ca_file is None:
        return LabwareTransferClient(
            (robot.host, robot.port), stations, insecure=True, step_timeout_s=step_timeout_s
        )
    return LabwareTransferClient(
        (robot.host, robot.port),
        stations,
        root_certs=deployment.ca_file.read_bytes(),
        step_timeout_s=step_timeout_s,
    )
