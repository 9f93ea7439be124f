"""TLS for our SiLA servers: one self-signed certificate per server, one CA file for clients.

SiLA 2 requires encrypted connections outside tests. Each server gets a certificate made by
sila2's own generator (it carries the server UUID in the SiLA extension and the host's IPs);
being self-signed, each certificate is its own CA. Clients trust the concatenation of them all,
written to one PEM file (`write_ca_bundle`); gRPC accepts such a bundle as root certificates.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from uuid import UUID

from sila2.server.encryption import generate_self_signed_certificate

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class ServerCredentials:
    private_key_pem: bytes
    certificate_pem: bytes


def self_signed_credentials(server_uuid: UUID, host: str) -> ServerCredentials:
    private_key, certificate = generate_self_signed_certificate(server_uuid, host)
    return ServerCredentials(private_key, certificate)


def write_ca_bundle(path: Path, certificates: Iterable[bytes]) -> Path:
    """Write the servers' certificates as one PEM bundle (world-readable: it holds no secret)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    bundle = b"".join(
        certificate if certificate.endswith(b"\n") else certificate + b"\n" for certificate in certificates
    )
    path.write_bytes(bundle)
    os.chmod(path, 0o644)
    logger.info("wrote the CA bundle for clients to %s", path)
    return path
