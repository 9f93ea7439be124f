"""SimulationController (SiLA core) for the robot: always in simulation mode, real mode refused.

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

NO_REAL_MODE = (
    "This server drives a simulated TIAGo++ in a PyBullet simulation; there is no real robot behind it, "
    "so it cannot switch to real mode"
)


class SimulationControllerImpl(SimulationControllerBase):
    def __init__(self, parent_server: Server) -> None:
        super().__init__(parent_server=parent_server)

    def get_SimulationMode(self, *, metadata: MetadataDict) -> bool:
        return True

    def StartSimulationMode(self, *, metadata: MetadataDict) -> StartSimulationMode_Responses:
        return StartSimulationMode_Responses()  # already simulating

    def StartRealMode(self, *, metadata: MetadataDict) -> StartRealMode_Responses:
        raise StartRealModeFailed(NO_REAL_MODE)
