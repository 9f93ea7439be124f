"""SimulationController (SiLA core) for a station: always in simulation mode, real mode refused.

It answers the scheduler's question "is this device simulated?" and nothing else. Resetting the
simulated world, injecting faults and pacing belong to the simulation-only feature; both coexist.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from sila2.server import MetadataDict

from ..generated.simulationcontroller import (
    SimulationControllerBase,
    StartRealMode_Responses,
    StartRealModeFailed,
    StartSimulationMode_Responses,
)

if TYPE_CHECKING:
    from ..server import Server


class SimulationControllerImpl(SimulationControllerBase):
    def __init__(self, parent_server: Server) -> None:
        super().__init__(parent_server=parent_server)
        self.no_real_mode = (
            f"This server stands for station {parent_server.station.station.name!r} in a PyBullet "
            "simulation; there is no real station behind it, so it cannot switch to real mode"
        )

    def get_SimulationMode(self, *, metadata: MetadataDict) -> bool:
        return True

    def StartSimulationMode(self, *, metadata: MetadataDict) -> StartSimulationMode_Responses:
        return StartSimulationMode_Responses()  # already simulating

    def StartRealMode(self, *, metadata: MetadataDict) -> StartRealMode_Responses:
        raise StartRealModeFailed(self.no_real_mode)
