# Created by sila2.code_generator 0.14.0 (new-package); hand-maintained since: regeneration never touches it.
"""The robot's SiLA server: the standard manipulator feature plus our motion and inventory features,
and the SiLA core features CancelController, LockController and SimulationController; with a
`SimulatedLab` (simulated robots only) also SimulatedLabController.

It is handed a `RobotController` (built on a running ROS bridge); the feature implementations
take their behaviour from it. `cancellable_commands` tracks the running robot commands for
CancelController; `serve_lock_controller` adds LockController with its gRPC guard.
"""

from __future__ import annotations

from uuid import UUID, uuid4

from sila2.server import SilaServer

from sila_labware.device.robot_controller import RobotController
from sila_labware.device.simulated_lab import SimulatedLab
from sila_labware.servers.finished_commands import FinishedCommandReaper
from sila_labware.servers.grpc_interceptors import serve_with_interceptors
from sila_labware.servers.initiation_checks import InitiationChecks, check_labware_transfer
from sila_labware.servers.locking import serve_lock_controller

from .cancellable_commands import CancellableCommands
from .feature_implementations.cancelcontroller_impl import CancelControllerImpl
from .feature_implementations.labwareinventory_impl import LabwareInventoryImpl
from .feature_implementations.labwaretransfermanipulatorcontroller_impl import (
    LabwareTransferManipulatorControllerImpl,
)
from .feature_implementations.mobilerobotcontroller_impl import MobileRobotControllerImpl
from .feature_implementations.simulatedlabcontroller_impl import SimulatedLabControllerImpl
from .feature_implementations.simulationcontroller_impl import SimulationControllerImpl
from .generated.cancelcontroller import CancelControllerFeature
from .generated.labwareinventory import LabwareInventoryFeature
from .generated.labwaretransfermanipulatorcontroller import LabwareTransferManipulatorControllerFeature
from .generated.mobilerobotcontroller import MobileRobotControllerFeature
from .generated.simulatedlabcontroller import SimulatedLabControllerFeature
from .generated.simulationcontroller import SimulationControllerFeature


class Server(SilaServer):
    def __init__(
        self,
        robot: RobotController,
        server_uuid: UUID | None = None,
        name: str | None = None,
        description: str | None = None,
        simulated_lab: SimulatedLab | None = None,
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
        self.cancellable_commands = CancellableCommands(self, robot)
        self.lockcontroller, lock_guard = serve_lock_controller(self)

        self.labwareinventory = LabwareInventoryImpl(self)
        self.set_feature_implementation(LabwareInventoryFeature, self.labwareinventory)

        self.labwaretransfermanipulatorcontroller = LabwareTransferManipulatorControllerImpl(self)
        self.set_feature_implementation(
            LabwareTransferManipulatorControllerFeature, self.labwaretransfermanipulatorcontroller
        )

        self.mobilerobotcontroller = MobileRobotControllerImpl(self)
        self.set_feature_implementation(MobileRobotControllerFeature, self.mobilerobotcontroller)

        self.cancelcontroller = CancelControllerImpl(self)
        self.set_feature_implementation(CancelControllerFeature, self.cancelcontroller)

        self.simulationcontroller = SimulationControllerImpl(self)
        self.set_feature_implementation(SimulationControllerFeature, self.simulationcontroller)

        if simulated_lab is not None:  # a simulated robot only: never offered for a real one
            self.simulatedlabcontroller = SimulatedLabControllerImpl(self, simulated_lab)
            self.set_feature_implementation(SimulatedLabControllerFeature, self.simulatedlabcontroller)

        # answers that must come before sila2 handles a call: a wrong lock token, a bad parameter
        initiation_checks = InitiationChecks()
        check_labware_transfer(
            initiation_checks, LabwareTransferManipulatorControllerFeature, robot.parameters
        )
        initiation_checks.add(
            MobileRobotControllerFeature, "DriveToPointOfInterest", robot.parameters.point_of_interest
        )
        serve_with_interceptors(self, [lock_guard, initiation_checks])
        # results of finished observable commands, kept for their lifetime by one thread
        self.finished_commands = FinishedCommandReaper(self).start()

    def stop(self, grace_period: float | None = None) -> None:
        self.finished_commands.stop()
        super().stop(grace_period)
