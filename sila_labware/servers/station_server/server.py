# Created by sila2.code_generator 0.14.0 (new-package); hand-maintained since: regeneration never touches it.

"""One station's SiLA server: the standard's passive-side feature, backed by a `StationController`,
and the SiLA core features LockController and SimulationController."""

from __future__ import annotations

from uuid import UUID, uuid4

from sila2.server import SilaServer

from sila_labware.device.station_controller import StationController
from sila_labware.servers.finished_commands import FinishedCommandReaper
from sila_labware.servers.grpc_interceptors import serve_with_interceptors
from sila_labware.servers.initiation_checks import InitiationChecks, check_labware_transfer
from sila_labware.servers.locking import serve_lock_controller

from .feature_implementations.labwaretransfersitecontroller_impl import LabwareTransferSiteControllerImpl
from .feature_implementations.simulationcontroller_impl import SimulationControllerImpl
from .generated.labwaretransfersitecontroller import LabwareTransferSiteControllerFeature
from .generated.simulationcontroller import SimulationControllerFeature


class Server(SilaServer):
    def __init__(
        self,
        station: StationController,
        server_uuid: UUID | None = None,
        name: str | None = None,
        description: str | None = None,
    ):
        if name is None:
            name = f"Station {station.station.name}"
        if description is None:
            description = (
                "A passive lab station whose plate nests a robot loads and unloads "
                "(SiLA labware transfer, passive side)."
            )
        super().__init__(
            server_name=name,
            server_description=description,
            server_type="LabwareStation",
            server_version="0.1",
            server_vendor_url="https://github.com/sila-labware/sila-labware",
            server_uuid=server_uuid if server_uuid is not None else uuid4(),
        )

        self.station = station
        self.lockcontroller, lock_guard = serve_lock_controller(self)

        self.labwaretransfersitecontroller = LabwareTransferSiteControllerImpl(self)
        self.set_feature_implementation(
            LabwareTransferSiteControllerFeature, self.labwaretransfersitecontroller
        )

        self.simulationcontroller = SimulationControllerImpl(self)
        self.set_feature_implementation(SimulationControllerFeature, self.simulationcontroller)

        # answers that must come before sila2 handles a call: a wrong lock token, a bad parameter
        initiation_checks = InitiationChecks()
        check_labware_transfer(initiation_checks, LabwareTransferSiteControllerFeature, station.parameters)
        serve_with_interceptors(self, [lock_guard, initiation_checks])
        # results of finished observable commands, kept for their lifetime by one thread
        self.finished_commands = FinishedCommandReaper(self).start()

    def stop(self, grace_period: float | None = None) -> None:
        self.finished_commands.stop()
        super().stop(grace_period)
