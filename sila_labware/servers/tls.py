"""TLS for our SiLA servers: one private CA per deployment, one certificate per server.

SiLA 2 requires encrypted connections outside tests. sila2 can make a self-signed certificate
per server, but each is then its own root, and all carry the same subject name: a client given
several of them as roots picks the wrong one by name and the handshake fails. So a deployment
makes its own small CA (kept in memory only, with a name of its own), signs one certificate per
server with it, and writes only the CA certificate to a file for clients.

A server certificate is what SiLA 2 Part B asks of a server whose certificate does not come from
a public authority: common name ``SiLA2``, the server UUID in the SiLA extension (OID
1.3.6.1.4.1.58583), the CA announced in the discovery record (`serving` does that). A client that
takes the CA from discovery alone checks that common name and connects; the host's addresses are
subject alternative names, so TLS checks the address as usual. The server's own name stands in
the organisational unit, for people reading the certificate.
"""

from __future__ import annotations

import datetime
import ipaddress
import logging
import secrets
import socket
from dataclasses import dataclass
from pathlib import Path
from uuid import UUID

from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

logger = logging.getLogger(__name__)

SILA_SERVER_UUID_OID = x509.ObjectIdentifier("1.3.6.1.4.1.58583")
VALIDITY = datetime.timedelta(days=365)


@dataclass(frozen=True)
class ServerCredentials:
    private_key_pem: bytes
    certificate_pem: bytes


SILA_UNTRUSTED_COMMON_NAME = "SiLA2"
"""The common name SiLA 2 Part B requires of a server certificate not issued by a public authority."""


def _name(common_name: str, unit: str = "") -> x509.Name:
    attributes = [x509.NameAttribute(NameOID.ORGANIZATION_NAME, "sila-labware deployment")]
    if unit:
        attributes.append(x509.NameAttribute(NameOID.ORGANIZATIONAL_UNIT_NAME, unit))
    return x509.Name([*attributes, x509.NameAttribute(NameOID.COMMON_NAME, common_name)])


def _machine_addresses() -> set[str]:
    """This machine's IPv4 addresses by its host name (for servers bound to 0.0.0.0)."""
    try:
        infos = socket.getaddrinfo(socket.gethostname(), None, socket.AF_INET)
    except OSError:
        return set()
    return {str(info[4][0]) for info in infos}


def _subject_alternative_names(host: str) -> list[x509.GeneralName]:
    """Names a client may use to reach the server: loopback always, plus the bound address or,
    for an unspecified bind address, the host name and its addresses."""
    dns_names = {"localhost"}
    addresses = {"127.0.0.1"}
    try:
        address = ipaddress.ip_address(host)
    except ValueError:
        dns_names.add(host)
    else:
        if address.is_unspecified:
            dns_names.add(socket.gethostname())
            addresses |= _machine_addresses()
        else:
            addresses.add(str(address))
    return [x509.DNSName(name) for name in sorted(dns_names)] + [
        x509.IPAddress(ipaddress.ip_address(value)) for value in sorted(addresses)
    ]


class CertificateAuthority:
    """A throw-away CA: its key never leaves memory; its certificate is what clients trust."""

    def __init__(self, common_name: str = "") -> None:
        """``common_name`` defaults to one unique to this CA, so that two labs' CAs differ by name
        as well as by key (a client that trusts both finds the right one)."""
        self._key = ec.generate_private_key(ec.SECP256R1())
        common_name = common_name or f"sila-labware CA {secrets.token_hex(4)}"
        now = datetime.datetime.now(datetime.timezone.utc)
        self._name = _name(common_name)
        self.certificate = (
            x509.CertificateBuilder()
            .subject_name(self._name)
            .issuer_name(self._name)
            .public_key(self._key.public_key())
            .serial_number(x509.random_serial_number())
            .not_valid_before(now - datetime.timedelta(hours=1))
            .not_valid_after(now + VALIDITY)
            .add_extension(x509.BasicConstraints(ca=True, path_length=0), critical=True)
            .add_extension(
                x509.KeyUsage(
                    digital_signature=False,
                    content_commitment=False,
                    key_encipherment=False,
                    data_encipherment=False,
                    key_agreement=False,
                    key_cert_sign=True,
                    crl_sign=True,
                    encipher_only=False,
                    decipher_only=False,
                ),
                critical=True,
            )
            .add_extension(x509.SubjectKeyIdentifier.from_public_key(self._key.public_key()), critical=False)
            .sign(self._key, hashes.SHA256())
        )

    @property
    def certificate_pem(self) -> bytes:
        return self.certificate.public_bytes(serialization.Encoding.PEM)

    def issue_server_credentials(self, server_uuid: UUID, server_name: str, host: str) -> ServerCredentials:
        """Key and certificate for one SiLA server, signed by this CA."""
        key = ec.generate_private_key(ec.SECP256R1())
        now = datetime.datetime.now(datetime.timezone.utc)
        certificate = (
            x509.CertificateBuilder()
            .subject_name(_name(SILA_UNTRUSTED_COMMON_NAME, unit=server_name))
            .issuer_name(self._name)
            .public_key(key.public_key())
            .serial_number(x509.random_serial_number())
            .not_valid_before(now - datetime.timedelta(hours=1))
            .not_valid_after(now + VALIDITY)
            .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
            .add_extension(x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH]), critical=False)
            .add_extension(x509.SubjectAlternativeName(_subject_alternative_names(host)), critical=False)
            .add_extension(
                x509.UnrecognizedExtension(SILA_SERVER_UUID_OID, str(server_uuid).encode("ascii")),
                critical=False,
            )
            .add_extension(
                x509.AuthorityKeyIdentifier.from_issuer_public_key(self._key.public_key()), critical=False
            )
            .sign(self._key, hashes.SHA256())
        )
        key_pem = key.private_bytes(
            serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
        )
        return ServerCredentials(key_pem, certificate.public_bytes(serialization.Encoding.PEM))

    def write_certificate(self, path: Path) -> Path:
        """Write the CA certificate for clients (world-readable: it holds no secret)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(self.certificate_pem)
        path.chmod(0o644)
        logger.info("wrote the CA certificate for clients to %s", path)
        return path
