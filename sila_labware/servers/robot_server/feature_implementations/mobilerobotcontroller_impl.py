"""MobileRobotController: base motions around the handovers, and what the robot is and carries.

Commands go to `RobotController` (dock, undock, drive, stop), each under its execution's cancel
token (`cancellable_commands`) so that CancelController can stop it; the observable properties follow
the robot side's /robot_state through the bridge's topic mirror. Listeners run on the ROS thread;
they push values into sila2's queues and wait (bounded) until sila2 serves them, so that a client
reading a property after a command's answer reads the state the command answered on.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TYPE_CHECKING

from sila2.server import MetadataDict, ObservableCommandInstance

from ros_bridge.workcell import RobotStatus
from sila_labware.device.errors import CommandSequenceError, MotionFailed, ParameterError
from sila_labware.device.inventory import Inventory
from sila_labware.servers.published_values import PublishedValues
from sila_labware.servers.sila_glue import progress_reporter, validation_error

from ..generated.mobilerobotcontroller import (
    Dock_Responses,
    DockingFailed,
    DriveToPointOfInterest_Responses,
    MobileRobotControllerBase,
    MobileRobotControllerFeature,
    MotionStopped,
    NavigationFailed,
    PointOfInterestName,
    RobotBusy,
    RobotDocked,
    StopMotion_Responses,
    Undock_Responses,
    UndockingFailed,
    UnknownPointOfInterest,
)

if TYPE_CHECKING:
    from ..server import Server

logger = logging.getLogger(__name__)

SILA_ROBOT_STATES = {
    "docked": "Docked",
    "idle": "Idle",
    "navigating": "Navigating",
    "manipulating": "Manipulating",
    "error": "Error",
}


def onboard_items(status: RobotStatus, inventory: Inventory) -> list[dict[str, object]]:
    """OnboardLabware: one entry per hotel slot whose sensor sees a plate, in slot order, by the
    name the robot side's inventory gives it ("" for a plate nobody named)."""
    items = []
    for reading in sorted(status.hotel, key=lambda reading: reading.slot):
        if not reading.occupied:
            continue
        record = inventory.at(reading.slot)
        items.append(
            {
                "InternalPosition": reading.slot.index,
                "LabwareUniqueID": record.labware_id if record else "",
                "LabwareType": (record.labware_type if record else "") or reading.labware_type,
            }
        )
    return items


class MobileRobotControllerImpl(MobileRobotControllerBase):
    def __init__(self, parent_server: Server) -> None:
        super().__init__(parent_server=parent_server)
        self.robot = parent_server.robot
        self.commands = parent_server.cancellable_commands
        self.published = PublishedValues(
            self, "RobotPose", "RobotState", "CurrentPointOfInterest", "OnboardLabware"
        )
        # Subscribers wait forever without a first value: publish the current state now.
        self._publish_status(self.robot.link.robot_status())
        self.robot.link.on_robot_status(self._publish_status)
        self.robot.inventory.add_listener(
            lambda _records: self._publish_onboard(self.robot.link.robot_status())
        )

    def _publish_status(self, status: RobotStatus) -> None:
        self.update_RobotPose({"X": status.x_m, "Y": status.y_m, "Theta": status.theta_rad})
        self.update_RobotState(SILA_ROBOT_STATES.get(status.state, "Error"))
        self.update_CurrentPointOfInterest(status.current_poi[:255])
        self._publish_onboard(status)

    def _publish_onboard(self, status: RobotStatus) -> None:
        self.update_OnboardLabware(onboard_items(status, self.robot.inventory))
        self.published.wait()  # before the bridge wakes a command that answers on this status

    def get_PointsOfInterest(self, *, metadata: MetadataDict) -> list[PointOfInterestName]:
        return list(self.robot.workcell.pois)

    def StopMotion(self, *, metadata: MetadataDict) -> StopMotion_Responses:
        self.robot.stop_motion()
        return StopMotion_Responses()

    def Dock(self, *, metadata: MetadataDict, instance: ObservableCommandInstance) -> Dock_Responses:
        instance.begin_execution()
        if self.robot.link.robot_status().docked:
            return Dock_Responses()
        self._run("Dock", instance, lambda: self.robot.dock(progress_reporter(instance)), DockingFailed)
        return Dock_Responses()

    def Undock(self, *, metadata: MetadataDict, instance: ObservableCommandInstance) -> Undock_Responses:
        instance.begin_execution()
        if not self.robot.link.robot_status().docked:
            return Undock_Responses()
        self._run("Undock", instance, lambda: self.robot.undock(progress_reporter(instance)), UndockingFailed)
        return Undock_Responses()

    def DriveToPointOfInterest(
        self,
        PointOfInterest: PointOfInterestName,
        *,
        metadata: MetadataDict,
        instance: ObservableCommandInstance,
    ) -> DriveToPointOfInterest_Responses:
        instance.begin_execution()
        self._run(
            "DriveToPointOfInterest",
            instance,
            lambda: self.robot.drive_to_poi(PointOfInterest, progress_reporter(instance)),
            NavigationFailed,
        )
        return DriveToPointOfInterest_Responses()

    def _run(
        self,
        command: str,
        instance: ObservableCommandInstance,
        motion: Callable[[], None],
        failure: type[Exception],
    ) -> None:
        try:
            with self.commands.running(instance):
                motion()
        except CommandSequenceError as error:
            raise RobotBusy(str(error)) from error
        except ParameterError as error:
            raise validation_error(MobileRobotControllerFeature, command, error) from error
        except MotionFailed as error:
            if error.error_code == "UNKNOWN_POI":
                raise UnknownPointOfInterest(error.message) from error
            if error.error_code == "DOCKED":
                raise RobotDocked(error.message) from error
            if error.error_code == "BUSY":
                raise RobotBusy(error.message) from error
            if error.error_code == "CANCELED":
                raise MotionStopped(error.message) from error
            raise failure(error.message) from error
