"""The SiLA interoperability test client (`sila2-interop-communication-tester`) against our servers.

Its `sila_service` suite checks SiLAService (server properties, metadata rejection, feature
listing) and validates every served feature definition against the standard's XML schema. It is
a pytest suite of its own: we run it in a subprocess per server, over TLS with the deployment's
CA, and fail if any of its tests fails or none ran.
"""

from __future__ import annotations

import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from sila_labware.deployment.stack import Deployment, ServedServer
from tests.helpers.sila_stack import start_stack

SUITE_TIMEOUT_S = 120.0


@pytest.fixture(scope="module")
def stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Deployment]:
    deployment = start_stack(tmp_path_factory.mktemp("interop"))
    yield deployment
    deployment.stop()


def start_sila_service_suite(served: ServedServer, ca_file: Path, report_dir: Path) -> subprocess.Popen[str]:
    """Start the tester's sila_service tests against one server, in a child process."""
    return subprocess.Popen(
        [
            sys.executable,
            "-m",
            "sila2_interop_communication_tester.test_client",
            "sila_service/",
            "--server-address",
            f"{served.host}:{served.port}",
            "--roots-cert-file",
            str(ca_file),
            "--timeout",
            "20",
            "--report-file",
            str(report_dir / f"interop-{served.port}.xml"),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )


def test_sila_service_suite_passes_against_every_server(stack: Deployment, tmp_path: Path) -> None:
    assert stack.ca_file is not None, "the deployment runs with TLS and writes its CA"
    roles = {served.role for served in stack.servers}
    assert roles == {"robot", "station"} and len(stack.servers) >= 3
    # One suite per server, all at once (each is mostly interpreter start-up and schema loading).
    suites = [(served, start_sila_service_suite(served, stack.ca_file, tmp_path)) for served in stack.servers]
    for served, suite in suites:
        try:
            output, _ = suite.communicate(timeout=SUITE_TIMEOUT_S)
        finally:
            if suite.poll() is None:
                suite.kill()
                suite.wait()
        summary = output.strip().splitlines()[-1] if output.strip() else ""
        failed_text = f"interop suite failed against {served.name} ({served.port}):\n{output[-4000:]}"
        assert suite.returncode == 0, failed_text
        passed = re.search(r"(\d+) passed", summary)
        assert passed and int(passed.group(1)) >= 20, f"{served.name}: too few tests ran: {summary}"
        assert not re.search(r"\d+ (failed|error|skipped)", summary), f"{served.name}: {summary}"
