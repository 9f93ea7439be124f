"""What only a simulated robot offers: a lab reset, injected faults, its pace.

Why apart from `RobotLink`: a real TIAGo++ serves the contract's actions and topics but none of
this; the SiLA feature built on it is served only when the robot side is simulated. The names are
the sim node's: `/reset_lab` (std_srvs/Trigger) and the node's parameters (`fault.*`,
`realtime_factor_cap`, `idle_realtime_factor`), set with the standard parameter service.

Threads: call from any thread except the ROS thread. Its service clients live on the robot link's
current runtime and are made anew when the link moves to another one.
"""

from __future__ import annotations

import logging
import threading

from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from std_srvs.srv import Trigger

from labware_model.readings import NestReading
from ros_bridge.errors import BridgeError
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime
from ros_bridge.services import ServiceCaller
from ros_bridge.workcell import RobotStatus

logger = logging.getLogger(__name__)

SIM_NODE = "/tiago_sim"
RESET_SERVICE = "/reset_lab"
RESET_TIMEOUT_S = 60.0


class SimulationRefused(BridgeError):
    """The simulation declined a request (busy robot, unknown plate, ...); the message says why."""


def parameter_value(value: str | float) -> ParameterValue:
    """A string stays a string; every number becomes a double (as the sim node declares them)."""
    if isinstance(value, str):
        return ParameterValue(type=ParameterType.PARAMETER_STRING, string_value=value)
    return ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=float(value))


class SimulationLink:
    """Reset, faults and pace of the simulated robot side behind `link`."""

    def __init__(self, link: RobotLink) -> None:
        self._link = link
        self._lock = threading.Lock()
        self._runtime: RosRuntime | None = None
        self._reset: ServiceCaller | None = None
        self._parameters: ServiceCaller | None = None

    def _callers(self) -> tuple[ServiceCaller, ServiceCaller]:
        with self._lock:
            runtime = self._link.runtime
            if self._runtime is not runtime or self._reset is None or self._parameters is None:
                self._runtime = runtime
                self._reset = ServiceCaller(runtime, Trigger, RESET_SERVICE)
                self._parameters = ServiceCaller(runtime, SetParameters, f"{SIM_NODE}/set_parameters")
            return self._reset, self._parameters

    def reset_lab(self, timeout_s: float = RESET_TIMEOUT_S) -> str:
        """Put the lab back as its world file describes; the robot side's own account of it."""
        reset, _ = self._callers()
        reset.wait_for_service(10.0)
        response = reset.call(Trigger.Request(), timeout_s)
        if not response.success:
            raise SimulationRefused(response.message)
        return str(response.message)

    def reports_after_reset(self, timeout_s: float = 10.0) -> tuple[RobotStatus, tuple[NestReading, ...]]:
        """The robot state and nest readings the robot side took after a reset returned: the state
        stamped after the one current now, then the next nest message (it follows the state)."""
        before = self._link.robot_status().stamp_s
        status = self._link.wait_for_robot_status(lambda s: s.stamp_s > before, timeout_s)
        return status, self._link.next_nest_readings(timeout_s)

    def set_parameters(self, values: dict[str, str | float], timeout_s: float = 10.0) -> None:
        """Set sim node parameters at once; SimulationRefused names the first one refused and why."""
        _, parameters = self._callers()
        parameters.wait_for_service(10.0)
        request = SetParameters.Request(
            parameters=[Parameter(name=name, value=parameter_value(value)) for name, value in values.items()]
        )
        results = parameters.call(request, timeout_s).results
        for name, result in zip(values, results, strict=True):
            if not result.successful:
                raise SimulationRefused(f"{name}: {result.reason}")
