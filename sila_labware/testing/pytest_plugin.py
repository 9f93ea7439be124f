"""pytest plugin (entry point ``pytest11``): a simulated lab for a downstream project's tests.

    def test_my_workflow(simulated_lab):
        simulated_lab.client.transfer(("station_a", 1), ("station_b", 1))

Fixtures:
- ``simulated_lab_session`` (session): one lab per test process, started at first use: world
  from ``--sila-lab-world`` (default: the default lab), pace from ``--sila-lab-pace`` (default: as
  fast as the machine allows); TLS with its CA in a temporary directory; no discovery.
- ``simulated_lab`` (function): the same lab, reset to its world file before the test runs.
- ``simulated_lab_addresses``: where the servers listen and the CA file, for your own SiLA client.

Isolation: every process (each pytest-xdist worker too) reserves its own ROS domain and picks
free ports on 127.0.0.1, so ``pytest -n 4`` runs four labs side by side.
"""

from __future__ import annotations

import statistics
from collections.abc import Iterator
from pathlib import Path

import pytest

from sila_labware.testing.lab import LabAddresses, SimulatedLabSession

DEFAULT_WORLD = Path(__file__).resolve().parents[2] / "lab_description" / "worlds" / "default.yaml"
SESSIONS = pytest.StashKey[list[SimulatedLabSession]]()


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("sila-lab", "simulated SiLA lab (sila-labware)")
    group.addoption(
        "--sila-lab-world",
        type=Path,
        default=None,
        help="world file of the simulated lab (default: the default lab)",
    )
    group.addoption(
        "--sila-lab-pace",
        type=float,
        default=None,
        help="times real time the simulation runs at (default: as fast as the machine allows)",
    )


@pytest.fixture(scope="session")
def simulated_lab_session(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[SimulatedLabSession]:
    world = request.config.getoption("--sila-lab-world") or DEFAULT_WORLD
    pace = request.config.getoption("--sila-lab-pace")
    session = SimulatedLabSession(Path(world).resolve(), tmp_path_factory.mktemp("sila_lab"), pace=pace)
    request.config.stash.setdefault(SESSIONS, []).append(session)
    with session:
        yield session


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter, config: pytest.Config) -> None:
    """One line per lab: how long it took to start and to reset (the figures a CI budget needs)."""
    for session in config.stash.get(SESSIONS, []):
        resets = session.resets_s
        line = f"simulated lab {session.world.name}: started in {session.started_in_s:.1f} s"
        if resets:
            line += (
                f", {len(resets)} resets, median {statistics.median(resets):.2f} s, max {max(resets):.2f} s"
            )
        terminalreporter.write_line(line)


@pytest.fixture
def simulated_lab(simulated_lab_session: SimulatedLabSession) -> SimulatedLabSession:
    simulated_lab_session.reset()
    return simulated_lab_session


@pytest.fixture
def simulated_lab_addresses(simulated_lab: SimulatedLabSession) -> LabAddresses:
    assert simulated_lab.addresses is not None
    return simulated_lab.addresses
