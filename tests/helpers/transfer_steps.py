"""The standard's transfer, step by step, for the reliability tests: any station to any station,
with each step's observable commands started together and awaited with a deadline.

Why not `run_demo`: it always moves the first station's plate to the second, and the fault tests
must resume a protocol part-way (after a failed GetLabware the source stays prepared for output).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from sila2.client import SilaClient

from labware_model.holders import GRIPPER, HotelSlot, Location, Nest
from sila_labware.deployment.stack import Deployment
from tests.helpers.sila_stack import client_for


def finish(instance: Any, timeout_s: float = 300.0) -> Any:
    """Wait for an observable command instance; return its responses or raise its SiLA error."""
    deadline = time.monotonic() + timeout_s
    while not instance.done:
        if time.monotonic() > deadline:
            raise TimeoutError(f"command not finished after {timeout_s:.0f} s")
        time.sleep(0.05)
    return instance.get_responses()


def wait_for_progress(instance: Any, at: float, timeout_s: float = 60.0) -> None:
    """Return once a running observable command reports ``at`` progress; it must not end before.

    Why: tests that act mid-command (cancel, kill the robot side) must not guess how long a
    command takes; the robot gets faster, a sleep then lands after the end.
    """
    deadline = time.monotonic() + timeout_s
    while (instance.progress or 0.0) < at:
        assert not instance.done, f"the command ended before {at:.0%} progress"
        assert time.monotonic() < deadline, f"no {at:.0%} progress in {timeout_s:.0f} s: {instance.progress}"
        time.sleep(0.02)
    assert not instance.done


def together(*starts: Callable[[], Any], timeout_s: float = 300.0) -> None:
    """Start observable commands at once, then wait for all; the first SiLA error propagates."""
    instances = [start() for start in starts]
    for instance in instances:
        finish(instance, timeout_s)


class Cell:
    """SiLA clients of one deployment: the robot and every station."""

    def __init__(self, deployment: Deployment) -> None:
        self.deployment = deployment
        self.robot: SilaClient = client_for(deployment, deployment.robot_server())
        assert deployment.workcell is not None
        self.stations: dict[str, SilaClient] = {
            station.name: client_for(deployment, deployment.station_server(station.name))
            for station in deployment.workcell.stations
        }

    @property
    def manipulator(self) -> Any:
        return self.robot.LabwareTransferManipulatorController

    def site(self, station: str) -> Any:
        return self.stations[station].LabwareTransferSiteController

    def robot_state(self) -> str:
        return self.robot.MobileRobotController.RobotState.get()

    def location(self, plate: str) -> tuple[bool, str, int]:
        found = self.robot.LabwareInventory.LocateLabware(LabwareUniqueID=plate).Location
        return found.Aboard, found.Position, found.Index

    def prepare_pick(self, source: tuple[str, int], plate: str, station_too: bool = True) -> None:
        starts = [
            lambda: self.manipulator.PrepareForInput(
                HandoverPosition=source, InternalPosition=1, LabwareType="", LabwareUniqueID=plate
            )
        ]
        if station_too:
            starts.append(
                lambda: self.site(source[0]).PrepareForOutput(HandoverPosition=source, InternalPosition=1)
            )
        together(*starts)

    def pick(self, source: tuple[str, int]) -> None:
        finish(self.manipulator.GetLabware(HandoverPosition=source, IntermediateActions=[]))
        finish(self.site(source[0]).LabwareRemoved(HandoverPosition=source))

    def place(self, destination: tuple[str, int], plate: str) -> None:
        together(
            lambda: self.site(destination[0]).PrepareForInput(
                HandoverPosition=destination, InternalPosition=1, LabwareType="", LabwareUniqueID=plate
            ),
            lambda: self.manipulator.PrepareForOutput(HandoverPosition=destination, InternalPosition=1),
        )
        finish(self.manipulator.PutLabware(HandoverPosition=destination, IntermediateActions=[]))
        finish(self.site(destination[0]).LabwareDelivered(HandoverPosition=destination))

    def transfer(self, source: tuple[str, int], destination: tuple[str, int], plate: str) -> None:
        """The whole standard transfer; raises the first SiLA error."""
        self.prepare_pick(source, plate)
        self.pick(source)
        self.place(destination, plate)

    def nest_occupied(self) -> dict[tuple[str, int], bool]:
        assert self.deployment.link is not None
        return {
            (reading.nest.station, reading.nest.sub_position): reading.occupied
            for reading in self.deployment.link.nest_readings()
        }

    def physical_location(self, plate: str) -> Location:
        """Where the simulation says the plate is: a nest, a hotel slot, the gripper, the floor
        (ground truth, for checks only)."""
        assert self.deployment.link is not None
        return self.deployment.link.check_placement(plate).location

    def reported_location(self, plate: str) -> Location:
        """Where the robot server's inventory says the plate is, read from its SiLA properties."""
        aboard, station, index = self.location(plate)
        if not aboard:
            return Nest(station, index)
        onboard = self.robot.MobileRobotController.OnboardLabware.get()
        slots = [item.InternalPosition for item in onboard if item.LabwareUniqueID == plate]
        return HotelSlot(slots[0]) if slots else GRIPPER
