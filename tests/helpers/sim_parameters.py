"""Set parameters of the robot-side nodes from tests (fault injection, pacing, estimates).

One place builds the ParameterValue for a Python value, so every test sets parameters alike.
"""

from __future__ import annotations

from rcl_interfaces.msg import Parameter
from rcl_interfaces.srv import SetParameters

from ros_bridge.runtime import RosRuntime
from ros_bridge.services import ServiceCaller
from ros_bridge.simulation_link import parameter_value


def parameter_request(name: str, value: str | float) -> SetParameters.Request:
    return SetParameters.Request(parameters=[Parameter(name=name, value=parameter_value(value))])


def set_node_parameter(runtime: RosRuntime, name: str, value: str | float, node: str = "/tiago_sim") -> None:
    """Set one parameter and assert the node accepted it."""
    caller = ServiceCaller(runtime, SetParameters, f"{node}/set_parameters")
    caller.wait_for_service(10.0)
    result = caller.call(parameter_request(name, value), 10.0).results[0]
    assert result.successful, result.reason
