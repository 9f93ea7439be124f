"""LabwareInventory: where each plate the robot handled is, from `sila_labware.device.inventory`.

A plate in the gripper counts as aboard at the internal position it was taken for (index 1 if
unknown); a plate whose location could not be established after a failed transfer is reported
by LocateLabware as UnknownLabware with that explanation, and left out of LabwareLocations.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from sila2.server import MetadataDict

from labware_model.holders import GRIPPER, UNKNOWN, HotelSlot, Nest, aboard
from sila_labware.device.inventory import LabwareRecord
from sila_labware.servers.published_values import PublishedValues

from ..generated.labwareinventory import LabwareInventoryBase, LocateLabware_Responses, UnknownLabware

if TYPE_CHECKING:
    from ..server import Server


def location_structure(record: LabwareRecord, gripper_slot: int) -> dict[str, object]:
    """The feature's LabwareLocation: a nest is (Position = station, Index = sub-position); aboard,
    a hotel slot is (Position = "", Index = slot) and the gripper counts as `gripper_slot`."""
    location = record.location
    if isinstance(location, Nest):
        position, index = location.station, location.sub_position
    elif isinstance(location, HotelSlot):
        position, index = "", location.index
    elif location == GRIPPER:
        position, index = "", gripper_slot
    else:  # unknown: never published (see LabwareInventoryImpl)
        position, index = "", 1
    return {
        "LabwareUniqueID": record.labware_id,
        "LabwareType": record.labware_type,
        "Aboard": aboard(location),
        "Position": position,
        "Index": max(1, index),
    }


class LabwareInventoryImpl(LabwareInventoryBase):
    def __init__(self, parent_server: Server) -> None:
        super().__init__(parent_server=parent_server)
        self.robot = parent_server.robot
        self.published = PublishedValues(self, "LabwareLocations")
        self._publish(self.robot.inventory.records())
        self.robot.inventory.add_listener(self._publish)

    def _gripper_slot(self) -> int:
        transfer = self.robot.sequence.transfer
        return transfer.internal_position if transfer is not None else 1

    def _publish(self, records: tuple[LabwareRecord, ...]) -> None:
        slot = self._gripper_slot()
        self.update_LabwareLocations(
            [location_structure(record, slot) for record in records if record.location != UNKNOWN]
        )
        self.published.wait()

    def LocateLabware(self, LabwareUniqueID: str, *, metadata: MetadataDict) -> LocateLabware_Responses:
        record = self.robot.inventory.locate(LabwareUniqueID)
        if record is None:
            raise UnknownLabware(f"this robot has not handled labware {LabwareUniqueID!r}")
        if record.location == UNKNOWN:
            raise UnknownLabware(
                f"labware {LabwareUniqueID!r} is lost: after the last failed transfer neither the robot "
                "nor any station sensor reports it"
            )
        return LocateLabware_Responses(Location=location_structure(record, self._gripper_slot()))
