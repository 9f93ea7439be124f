"""Free TCP ports on 127.0.0.1 for a lab's SiLA servers, so parallel runs never collide."""

from __future__ import annotations

import socket
from collections.abc import Iterator

from sila_labware.deployment.port_blocks import claim_free_block


def free_port_base(count: int, candidates: range | None = None) -> int:
    """A port with ``count`` free ports on 127.0.0.1 from it on: the first such in ``candidates``,
    else one the kernel hands out as ephemeral (so parallel runs rarely pick the same). The block is
    reserved for this process as a campaign's trials reserve theirs (`port_blocks`)."""
    for base in candidates if candidates is not None else _ephemeral_ports(50):
        ports = range(base, base + count)
        if ports.stop <= 65536 and claim_free_block(ports):  # locked: a campaign beside never takes it
            return base
    raise RuntimeError(f"no block of {count} free ports found")


def _ephemeral_ports(count: int) -> Iterator[int]:
    for _attempt in range(count):
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            port = probe.getsockname()[1]
        yield port
