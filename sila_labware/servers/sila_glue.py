"""Small translations between our robot logic and the sila2 library, shared by both servers.

Threads: `progress_reporter`'s callable is called on the ROS thread (goal feedback) and on the
command's handler thread (its last report); sila2's command instance notifies subscribers
itself, so the call is short.
"""

from __future__ import annotations

import logging
from datetime import timedelta

from sila2.framework import ValidationError
from sila2.framework.feature import Feature
from sila2.framework.fully_qualified_identifier import FullyQualifiedCommandParameterIdentifier
from sila2.server import ObservableCommandInstance

from ros_bridge.progress import ProgressReport
from sila_labware.device.errors import ParameterError

logger = logging.getLogger(__name__)


def validation_error(feature: Feature, command: str, error: ParameterError) -> ValidationError:
    """A SiLA validation error naming the parameter (as clients expect it, fully qualified)."""
    validation = ValidationError(error.message)
    validation.parameter_fully_qualified_identifier = FullyQualifiedCommandParameterIdentifier(
        f"{feature.fully_qualified_identifier}/Command/{command}/Parameter/{error.parameter}"
    )
    return validation


def progress_reporter(instance: ObservableCommandInstance) -> ProgressReport:
    """Write a command's (progress, remaining seconds) into its SiLA command instance.

    The numbers come from the RobotController's `CommandProgress` (ros_bridge.progress), which
    owns the rule that a command's progress stays in 0..1 and never goes down, across all the
    goals of the command; this only writes them, in the order they come."""

    def report(progress: float, remaining_s: float | None) -> None:
        try:
            instance.progress = progress
            if remaining_s is not None:  # no estimate: leave it unset rather than claim 0
                instance.estimated_remaining_time = timedelta(seconds=remaining_s)
        except Exception:  # noqa: BLE001 - a closed instance must not break the ROS thread
            logger.debug("could not update a command instance", exc_info=True)

    return report


def handover_position(position: str, sub_position: int) -> dict[str, object]:
    """The standard's HandoverPosition structure as sila2 takes it."""
    return {"Position": position, "SubPosition": sub_position}
