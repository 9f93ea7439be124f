"""SimulatedLabController (ours): reset the simulated lab, inject faults, set the pace.

Served only when the robot side is simulated (the deployment hands the server a `SimulatedLab`);
the behaviour lives in sila_labware.device.simulated_lab, this maps it onto SiLA errors.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from sila2.server import MetadataDict

from sila_labware.device.errors import ParameterError
from sila_labware.device.simulated_lab import RobotBusy as LabRobotBusy
from sila_labware.device.simulated_lab import SimulatedLab, SimulationRequestFailed
from sila_labware.servers.sila_glue import validation_error

from ..generated.simulatedlabcontroller import (
    ClearFaults_Responses,
    FaultRefused,
    InjectFault_Responses,
    ResetFailed,
    ResetLab_Responses,
    RobotBusy,
    SetPace_Responses,
    SimulatedLabControllerBase,
    SimulatedLabControllerFeature,
)

if TYPE_CHECKING:
    from ..server import Server


class SimulatedLabControllerImpl(SimulatedLabControllerBase):
    def __init__(self, parent_server: Server, lab: SimulatedLab) -> None:
        super().__init__(parent_server=parent_server)
        self.lab = lab

    def get_SimulatedTime(self, *, metadata: MetadataDict) -> float:
        status = self.lab.robot.link.latest_robot_status()
        return 0.0 if status is None else status.stamp_s

    def get_RealTimeFactor(self, *, metadata: MetadataDict) -> float:
        return self.lab.robot.pace.factor

    def get_Pace(self, *, metadata: MetadataDict) -> float:
        return self.lab.pace

    def get_ActiveFaults(self, *, metadata: MetadataDict) -> list[str]:
        return self.lab.active_faults

    def ResetLab(self, *, metadata: MetadataDict) -> ResetLab_Responses:
        try:
            self.lab.reset()
        except LabRobotBusy as busy:
            raise RobotBusy(str(busy)) from busy
        except SimulationRequestFailed as failed:
            if "busy" in str(failed):
                raise RobotBusy(str(failed)) from failed
            raise ResetFailed(str(failed)) from failed
        return ResetLab_Responses()

    def InjectFault(self, Fault: str, Target: str, *, metadata: MetadataDict) -> InjectFault_Responses:
        try:
            self.lab.inject_fault(Fault, Target)
        except ParameterError as error:
            raise validation_error(SimulatedLabControllerFeature, "InjectFault", error) from error
        except LabRobotBusy as busy:
            raise RobotBusy(str(busy)) from busy
        except SimulationRequestFailed as failed:
            raise FaultRefused(str(failed)) from failed
        return InjectFault_Responses()

    def ClearFaults(self, *, metadata: MetadataDict) -> ClearFaults_Responses:
        try:
            self.lab.clear_faults()
        except SimulationRequestFailed as failed:
            raise FaultRefused(str(failed)) from failed
        return ClearFaults_Responses()

    def SetPace(self, Pace: float, *, metadata: MetadataDict) -> SetPace_Responses:
        try:
            self.lab.set_pace(Pace)
        except ParameterError as error:
            raise validation_error(SimulatedLabControllerFeature, "SetPace", error) from error
        except SimulationRequestFailed as failed:
            raise FaultRefused(str(failed)) from failed
        return SetPace_Responses()
