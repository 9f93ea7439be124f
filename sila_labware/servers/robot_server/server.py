# Created by sila2.code_generator 0.14.0 (new-package); hand-maintained since: regeneration never touches it.
"""The robot's SiLA server: the standard manipulator feature plus our motion and inventory features.

It is handed a `RobotController` (built on a running ROS bridge); the feature implementations
take their behaviour from it.
"""

from __future__ import annotations

from uuid import UUID, uuid4

from sila2.server import SilaServer

from sila_labware.device.robot_controller import RobotController
from sila_labware.servers.initiation_checks import InitiationChecks, check_labware_transfer

from .feature_implementations.labwareinventory_impl import LabwareInventoryImpl
from .feature_implementations.labwaretransfermanipulatorcontroller_impl import (
    LabwareTransferManipulatorControllerImpl,
)
from .feature_implementations.mobilerobotcontroller_impl import MobileRobotControllerImpl
from .generated.labwareinventory import LabwareInventoryFeature
from .generated.labwaretransfermanipulatorcontroller import LabwareTransferManipulatorControllerFeature
from .generated.mobilerobotcontroller import MobileRobotControllerFeature


class Server(SilaServer):
    def __init__(
        self,
        robot: RobotController,
        server_uuid: UUID | None = None,
        name: str | None = None,
        description: str | None = None,
    ):
        if name is None:
            name = "TIAGo Labware Robot"
        if description is None:
            description = (
                "A TIAGo++ mobile manipulator that moves labware between lab stations "
                "(SiLA labware transfer, active side)."
            )
        super().__init__(
            server_name=name,
            server_description=description,
            server_type="MobileManipulator",
            server_version="0.1",
            server_vendor_url="https://github.com/sila-labware/sila-labware",
            server_uuid=server_uuid if server_uuid is not None else uuid4(),
        )
        self.robot = robot
        self.initiation_checks = InitiationChecks.install(self)

        self.labwareinventory = LabwareInventoryImpl(self)
        self.set_feature_implementation(LabwareInventoryFeature, self.labwareinventory)

        self.labwaretransfermanipulatorcontroller = LabwareTransferManipulatorControllerImpl(self)
        self.set_feature_implementation(
            LabwareTransferManipulatorControllerFeature, self.labwaretransfermanipulatorcontroller
        )

        self.mobilerobotcontroller = MobileRobotControllerImpl(self)
        self.set_feature_implementation(MobileRobotControllerFeature, self.mobilerobotcontroller)

        check_labware_transfer(
            self.initiation_checks, LabwareTransferManipulatorControllerFeature, robot.parameters
        )
        self.initiation_checks.add(
            MobileRobotControllerFeature, "DriveToPointOfInterest", robot.parameters.point_of_interest
        )
