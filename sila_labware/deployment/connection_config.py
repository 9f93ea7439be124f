"""What a client needs to reach a running deployment, for people and for tooling.

Why: `serve --print-config json` lets a pipeline start the lab and configure its scheduler from
one JSON document on stdout instead of parsing log lines. The document names, per SiLA server,
its role, name, address, server UUID and the fully qualified identifiers of the features it
serves, and the CA file clients must trust (null when the servers run without TLS).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, TextIO

from sila_labware.deployment.json_outcome import JsonOutput, outcome_fields

if TYPE_CHECKING:
    from sila_labware.deployment.stack import Deployment, ServedServer

CONFIG_FORMATS = ("json",)


def add_print_config_argument(parser: Any) -> None:
    parser.add_argument(
        "--print-config",
        choices=CONFIG_FORMATS,
        default=None,
        help="once the servers are up, write their connection details to stdout as one JSON "
        "document (the human-readable listing then goes to stderr)",
    )


def server_config(served: ServedServer) -> dict[str, Any]:
    """One server's entry: how to reach it, who it is, what it offers."""
    return {
        "role": served.role,
        "name": served.name,
        "station": served.station or None,
        "host": served.host,
        "port": served.port,
        "server_uuid": str(served.server.server_uuid),
        "features": sorted(
            str(feature.fully_qualified_identifier) for feature in served.server.features.values()
        ),
    }


def connection_config(deployment: Deployment) -> dict[str, Any]:
    """The whole deployment's connection details (see the module docstring)."""
    ca_file = deployment.ca_file
    return {
        "ca_file": None if ca_file is None else str(ca_file.resolve()),
        "pace": deployment.options.pace,
        "ros_domain_id": deployment.domain_id,
        "servers": [server_config(served) for served in deployment.servers],
    }


def write_config(deployment: Deployment, stream: TextIO) -> None:
    """The JSON document, on one line, flushed (a reader may wait for it line by line), with the
    fields every machine-readable output carries (json_outcome; exit_code null: serve runs on)."""
    JsonOutput.write({**connection_config(deployment), **outcome_fields(exit_code=None)}, stream)


def print_servers(deployment: Deployment, stream: TextIO) -> None:
    """The human-readable listing: servers, CA file, robot-side processes, ROS domain."""
    for served in deployment.servers:
        stream.write(f"{served.role:8} {served.name:32} {served.host}:{served.port}\n")
    if deployment.ca_file is not None:
        stream.write(f"CA file for clients: {deployment.ca_file.resolve()}\n")
    for child in deployment.children.children:
        stream.write(f"robot side: {child.name} pid {child.popen.pid}\n")
    stream.write(f"ROS domain: {deployment.domain_id}\n")
    stream.flush()
