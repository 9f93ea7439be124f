"""Parameter checks that answer on the initiating call of an observable command, as SiLA asks.

Why: the standard issues a validation error before a command's execution starts, on the call
that initiates it. sila2 0.14 checks only the feature definition's constraints there; it creates
the execution (and answers with its UUID) before any code of ours runs, so a check of ours (an
unknown station, a sub-position beyond the nests, an unknown point of interest) could only fail
the execution afterwards: the client saw running -> finishedWithError. These checks need no
motion and no robot state, so they can answer at once.

How: a gRPC server interceptor in front of the initiation RPC of each checked command. It
unpacks the parameters as sila2 does (`Command.parameters.to_native_type`), calls the device's
check with them, and answers a `ParameterError` with a SiLA validation error naming the
parameter; otherwise the call goes on to sila2 unchanged. `grpc_interceptors` puts it in front
of the server.

Threads: checks run on gRPC's handler threads, concurrently; they must be pure (no robot state).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

import grpc
from sila2.framework import Feature, ValidationError
from sila2.framework.utils import raise_as_rpc_error

from sila_labware.device.errors import ParameterError
from sila_labware.device.validation import DeviceParameters
from sila_labware.servers.refusal_log import describe_refusal
from sila_labware.servers.sila_glue import validation_error

logger = logging.getLogger(__name__)

CommandCheck = Callable[..., None]
"""Called with the command's parameters in their native types, in the order the feature defines
them; raises ParameterError naming the parameter for a value this device refuses."""


class InitiationChecks(grpc.ServerInterceptor):
    """The checks of one server, by feature and command (see the module docstring)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._checks: dict[str, tuple[Feature, str, CommandCheck]] = {}

    def add(self, feature: Feature, command: str, check: CommandCheck) -> None:
        """Run `check` on every initiation of `feature`'s observable command `command`."""
        with self._lock:
            self._checks[f".{feature._identifier}/{command}"] = (feature, command, check)

    def intercept_service(self, continuation: Callable[[Any], Any], handler_call_details: Any) -> Any:
        handler = continuation(handler_call_details)
        method: str = handler_call_details.method or ""
        with self._lock:
            checked = next((entry for suffix, entry in self._checks.items() if method.endswith(suffix)), None)
        if handler is None or checked is None or handler.unary_unary is None:
            return handler
        feature, command, check = checked
        initiate = handler.unary_unary

        def initiate_if_valid(request: Any, context: grpc.ServicerContext) -> Any:
            try:
                parameters = feature[command].parameters.to_native_type(request)
            except ValidationError:
                return initiate(request, context)  # a constraint of the definition: sila2 answers it
            try:
                check(*parameters)
            except ParameterError as error:
                refusal = validation_error(feature, command, error)
                logger.warning("%s", describe_refusal(refusal))
                raise_as_rpc_error(refusal, context)
            return initiate(request, context)

        return grpc.unary_unary_rpc_method_handler(
            initiate_if_valid,
            request_deserializer=handler.request_deserializer,
            response_serializer=handler.response_serializer,
        )


def check_labware_transfer(checks: InitiationChecks, feature: Feature, parameters: DeviceParameters) -> None:
    """The standard's commands of either labware-transfer feature (manipulator or site), with what
    each needs of its parameters; commands the feature lacks are skipped."""
    by_command: dict[str, CommandCheck] = {
        "PrepareForInput": lambda handover, internal, labware_type, labware_id: parameters.prepare(
            handover.Position, handover.SubPosition, internal, labware_type, labware_id
        ),
        "PrepareForOutput": lambda handover, internal: parameters.prepare(
            handover.Position, handover.SubPosition, internal
        ),
        "GetLabware": lambda handover, actions: parameters.transfer(
            handover.Position, handover.SubPosition, actions
        ),
        "PutLabware": lambda handover, actions: parameters.transfer(
            handover.Position, handover.SubPosition, actions
        ),
        "LabwareDelivered": lambda handover: parameters.handover(handover.Position, handover.SubPosition),
        "LabwareRemoved": lambda handover: parameters.handover(handover.Position, handover.SubPosition),
    }
    for command, check in by_command.items():
        try:
            feature[command]
        except KeyError:
            continue
        checks.add(feature, command, check)
