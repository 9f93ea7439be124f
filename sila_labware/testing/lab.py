"""One simulated lab for a test session: start it, reach it, reset it between tests, stop it.

Why a class of its own: the pytest plugin is its main user, but a CI script or a notebook wants
the same thing without pytest (`with SimulatedLabSession(world) as lab: ...`). The lab runs in
this process (bridge, SiLA servers) and its children (sim node, sequencer), in a ROS domain
reserved for this process and on free ports of 127.0.0.1, with TLS and its CA written to `workdir`.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType

from sila2.client import SilaClient

from ros_bridge.domain import reserve_domain_id
from sila_labware.client.records import Address
from sila_labware.client.transfer_client import LabwareTransferClient
from sila_labware.deployment.stack import Deployment, DeploymentOptions
from sila_labware.testing.ports import free_port_base

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class LabAddresses:
    """Where the lab's servers listen, for users who bring their own SiLA client."""

    robot: Address
    stations: dict[str, Address]
    ca_file: Path  # PEM of the CA that signed every server's certificate

    def root_certs(self) -> bytes:
        return self.ca_file.read_bytes()


class SimulatedLabSession:
    """A started lab (see the module docstring); `client` speaks the standard transfer to it."""

    def __init__(
        self, world: Path, workdir: Path, *, pace: float | None = None, discovery: bool = False
    ) -> None:
        self.world = world
        self.workdir = workdir
        self.pace = pace
        self.discovery = discovery
        self.deployment: Deployment | None = None
        self.addresses: LabAddresses | None = None
        self.client: LabwareTransferClient | None = None
        self.started_in_s = 0.0
        self.resets_s: list[float] = []
        self._robot_sila: SilaClient | None = None

    def start(self) -> SimulatedLabSession:
        started = time.monotonic()
        self.workdir.mkdir(parents=True, exist_ok=True)
        deployment = Deployment(
            DeploymentOptions(
                world=self.world,
                host="127.0.0.1",
                port_base=free_port_base(8),
                ca_file=self.workdir / "ca.pem",
                discovery=self.discovery,
                domain_id=reserve_domain_id(),
                log_dir=self.workdir / "logs",
                pace=self.pace,
            )
        )
        self.deployment = deployment
        try:
            deployment.start()
            assert deployment.ca_file is not None
            robot = deployment.robot_server()
            self.addresses = LabAddresses(
                (robot.host, robot.port),
                {s.station: (s.host, s.port) for s in deployment.servers if s.role == "station"},
                deployment.ca_file,
            )
            self.client = LabwareTransferClient(
                self.addresses.robot,
                list(self.addresses.stations.values()),
                root_certs=self.addresses.root_certs(),
            )
        except BaseException:
            self.stop()
            raise
        self.started_in_s = time.monotonic() - started
        logger.info(
            "simulated lab %s up in %.1f s (logs: %s)", self.world.name, self.started_in_s, self.workdir
        )
        return self

    def sila_client(self, station: str | None = None) -> SilaClient:
        """A plain sila2 client of the robot's server, or of a station's."""
        assert self.addresses is not None, "the lab is not started"
        host, port = self.addresses.robot if station is None else self.addresses.stations[station]
        return SilaClient(host, port, root_certs=self.addresses.root_certs())

    def reset(self) -> float:
        """The lab as its world file describes, asked over SiLA (SimulatedLabController.ResetLab) as
        any client would; returns its wall seconds."""
        if self._robot_sila is None:
            self._robot_sila = self.sila_client()
        started = time.monotonic()
        self._robot_sila.SimulatedLabController.ResetLab()
        took = time.monotonic() - started
        self.resets_s.append(took)
        return took

    def stop(self) -> None:
        if self._robot_sila is not None:
            self._robot_sila.close()
            self._robot_sila = None
        if self.client is not None:
            self.client.close()
            self.client = None
        if self.deployment is not None:
            self.deployment.stop()
            self.deployment = None

    def __enter__(self) -> SimulatedLabSession:
        return self.start()

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        self.stop()
