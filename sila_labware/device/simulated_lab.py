"""The simulated lab behind the robot: reset, injected faults and pace (SimulatedLabController).

Why here and not in the simulation: a reset must leave the SiLA side true as well, so the robot's
command order and the stations' nest phases go back to idle and the inventory takes the plates
from the robot side's reports again. A fault is only ever set in the simulation; the robot learns
of it from its sensors.

Threads: SiLA handler threads. A reset holds the robot's command sequence in "moving", so no robot
command starts during it and none may run when it begins.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Sequence
from typing import Protocol

from labware_model.readings import NestReading
from ros_bridge.errors import BridgeError
from ros_bridge.workcell import RobotStatus
from sila_labware.device.errors import CommandSequenceError, ParameterError
from sila_labware.device.robot_controller import RobotController
from sila_labware.device.station_controller import StationController

logger = logging.getLogger(__name__)

FAULT_PARAMETERS = {
    "RemovePlate": "fault.remove_plate",
    "DropPlate": "fault.drop_plate",
    "KnockPlate": "fault.knock_plate",
    "OccludeMarker": "fault.occlude_marker",
    "BlockPath": "fault.block_path",
}
FAULTS_DURING_A_COMMAND = frozenset({"DropPlate", "KnockPlate", "OccludeMarker", "BlockPath"})
TARGET_REFUSALS = ("unknown plate", "unknown station", "fault.block_path")
"""How the sim node's refusal of a fault's target begins (tiago_sim.sim_node.node)."""
REPORT_AFTER_RESET_S = 10.0  # the robot side reports its state at 20 Hz; generous under load
INVENTORY_AFTER_RESET_S = 2.0  # the inventory follows the next pair of reports (2 Hz and faster)


class SimulationBackend(Protocol):
    """The simulation's controls (ros_bridge.simulation_link.SimulationLink in a deployment)."""

    def reset_lab(self, timeout_s: float = ...) -> str: ...

    def set_parameters(self, values: dict[str, str | float], timeout_s: float = ...) -> None: ...

    def reports_after_reset(self, timeout_s: float = ...) -> tuple[RobotStatus, tuple[NestReading, ...]]: ...


class RobotBusy(Exception):
    """A robot command runs; the message names it."""


class SimulationRequestFailed(Exception):
    """The simulation refused or failed; the message says why."""


class UnknownFaultTarget(ParameterError):
    """The fault's target names no plate or station of the lab, or is no distance BlockPath takes."""

    def __init__(self, message: str) -> None:
        super().__init__("Target", message)


class SimulatedLab:
    """Reset, faults and pace of the lab served by `robot` and `stations`."""

    def __init__(
        self,
        simulation: SimulationBackend,
        robot: RobotController,
        stations: Sequence[StationController],
        pace: float | None = None,
    ) -> None:
        self.simulation = simulation
        self.robot = robot
        self.stations = tuple(stations)
        self.pace = pace or 0.0
        robot.pace.set_nominal(self.pace)
        self._faults: list[str] = []
        self._lock = threading.Lock()

    @property
    def active_faults(self) -> list[str]:
        with self._lock:
            return list(self._faults)

    def reset(self) -> str:
        """The lab as its world file describes; raises RobotBusy or SimulationRequestFailed."""
        try:
            self.robot.sequence.begin_motion("ResetLab")
        except CommandSequenceError as busy:
            raise RobotBusy(str(busy)) from busy
        try:
            report = self._call(self.simulation.reset_lab)
            with self._lock:
                self._faults.clear()
            for station in self.stations:
                station.sequence.reset()
            self._take_inventory_anew()
        finally:
            self.robot.sequence.finish_motion()
        logger.info("%s", report)
        return report

    def inject_fault(self, fault: str, target: str) -> None:
        """Set one fault in the simulation (see the feature's description for each)."""
        if fault not in FAULT_PARAMETERS:
            raise ParameterError("Fault", f"unknown fault {fault!r}: one of {', '.join(FAULT_PARAMETERS)}")
        stations = [name for name, _ in self.robot.handover_positions()]
        if fault == "OccludeMarker" and target not in stations:
            raise UnknownFaultTarget(f"unknown station {target!r}: the lab has {', '.join(stations)}")
        if fault not in FAULTS_DURING_A_COMMAND:
            try:
                self.robot.sequence.begin_motion(f"InjectFault {fault}")
            except CommandSequenceError as busy:
                raise RobotBusy(str(busy)) from busy
            try:
                self._set_fault(fault, target)
            finally:
                self.robot.sequence.finish_motion()
        else:
            self._set_fault(fault, target)

    def clear_faults(self) -> None:
        self._call(lambda: self.simulation.set_parameters({name: "" for name in FAULT_PARAMETERS.values()}))
        with self._lock:
            self._faults.clear()

    def set_pace(self, pace: float) -> None:
        """Simulated seconds per wall second; 0: as fast as the machine allows (idle at real time)."""
        if not 0.0 <= pace <= 1000.0:  # also refuses nan
            raise ParameterError("Pace", f"pace {pace:g} is outside 0 .. 1000")
        self._call(
            lambda: self.simulation.set_parameters(
                {"realtime_factor_cap": pace, "idle_realtime_factor": pace if pace > 0 else 1.0}
            )
        )
        self.pace = pace
        self.robot.pace.set_nominal(pace)

    def _set_fault(self, fault: str, target: str) -> None:
        try:
            self.simulation.set_parameters({FAULT_PARAMETERS[fault]: target})
        except BridgeError as error:
            if any(refusal in str(error) for refusal in TARGET_REFUSALS):
                raise UnknownFaultTarget(str(error).split(": ", 1)[-1]) from error
            raise SimulationRequestFailed(str(error)) from error
        with self._lock:
            self._faults.append(f"{fault} {target}")

    def _take_inventory_anew(self) -> None:
        """The robot side's inventory follows its sensors once the reset lab reports (plates keep
        their names where their labels are read again): wait for that, briefly."""
        revision = self.robot.inventory.revision
        self.simulation.reports_after_reset(REPORT_AFTER_RESET_S)
        try:
            self.robot.inventory.replace(
                self.robot.link.wait_for_inventory(lambda s: s.revision > revision, INVENTORY_AFTER_RESET_S)
            )
        except BridgeError:
            pass  # nothing moved under a name: the inventory had nothing to change

    @staticmethod
    def _call(request) -> str:  # noqa: ANN001 - a zero-argument callable
        try:
            return request() or ""
        except BridgeError as error:
            raise SimulationRequestFailed(str(error)) from error
