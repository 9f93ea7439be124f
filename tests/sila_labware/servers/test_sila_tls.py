"""The deployment CA: server certificates chain to it and carry what SiLA clients check."""

from __future__ import annotations

import ipaddress
import uuid
from pathlib import Path

import pytest
from cryptography import x509
from cryptography.exceptions import InvalidSignature
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import NameOID

from sila_labware.servers.tls import SILA_SERVER_UUID_OID, CertificateAuthority


def test_server_certificates_chain_to_the_ca_and_carry_the_server_uuid(tmp_path: Path) -> None:
    authority = CertificateAuthority()
    server_uuid = uuid.uuid4()
    credentials = authority.issue_server_credentials(server_uuid, "TIAGo Labware Robot", "127.0.0.1")
    certificate = x509.load_pem_x509_certificate(credentials.certificate_pem)
    ca_certificate = x509.load_pem_x509_certificate(
        authority.write_certificate(tmp_path / "ca.pem").read_bytes()
    )

    assert certificate.issuer == ca_certificate.subject
    ca_certificate.public_key().verify(
        certificate.signature,
        certificate.tbs_certificate_bytes,
        ec.ECDSA(certificate.signature_hash_algorithm),
    )
    assert ca_certificate.extensions.get_extension_for_class(x509.BasicConstraints).value.ca
    assert not certificate.extensions.get_extension_for_class(x509.BasicConstraints).value.ca
    sila_extension = certificate.extensions.get_extension_for_oid(SILA_SERVER_UUID_OID).value
    assert sila_extension.value == str(server_uuid).encode("ascii")
    names = certificate.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    assert ipaddress.ip_address("127.0.0.1") in names.get_values_for_type(x509.IPAddress)
    assert b"PRIVATE KEY" in credentials.private_key_pem
    assert b"PRIVATE KEY" not in (tmp_path / "ca.pem").read_bytes()


def test_each_deployment_has_its_own_ca() -> None:
    first, second = CertificateAuthority(), CertificateAuthority()
    assert first.certificate_pem != second.certificate_pem
    leaf = x509.load_pem_x509_certificate(
        second.issue_server_credentials(uuid.uuid4(), "Station station_a", "127.0.0.1").certificate_pem
    )
    with pytest.raises(InvalidSignature):
        first.certificate.public_key().verify(
            leaf.signature, leaf.tbs_certificate_bytes, ec.ECDSA(leaf.signature_hash_algorithm)
        )


def test_server_certificates_carry_the_common_name_sila_part_b_asks_of_untrusted_servers() -> None:
    """A client that takes the CA from the discovery record refuses any other common name."""
    authority = CertificateAuthority()
    certificate = x509.load_pem_x509_certificate(
        authority.issue_server_credentials(uuid.uuid4(), "Station station_a", "127.0.0.1").certificate_pem
    )
    assert [a.value for a in certificate.subject.get_attributes_for_oid(NameOID.COMMON_NAME)] == ["SiLA2"]
    units = certificate.subject.get_attributes_for_oid(NameOID.ORGANIZATIONAL_UNIT_NAME)
    assert [a.value for a in units] == ["Station station_a"]
    ca_name, other_ca_name = (
        ca.certificate.subject.get_attributes_for_oid(NameOID.COMMON_NAME)[0].value
        for ca in (authority, CertificateAuthority())
    )
    assert ca_name.startswith("sila-labware CA ") and ca_name != other_ca_name
