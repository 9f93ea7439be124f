"""Robot logic without ROS or SiLA: command order, parameter checks, inventory."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from labware_model.holders import UNKNOWN, HotelSlot, Nest
from labware_model.inventory import LabwareRecord
from labware_model.readings import HotelSlotReading
from ros_bridge.workcell import InventorySnapshot, RobotStatus
from sila_labware.device.errors import CommandSequenceError, ParameterError
from sila_labware.device.inventory import Inventory
from sila_labware.device.sequences import (
    ManipulatorPhase,
    ManipulatorSequence,
    NestPhase,
    PreparedTransfer,
    SiteSequence,
)
from sila_labware.device.validation import (
    MAX_TEXT_LENGTH,
    check_handover,
    check_intermediate_actions,
    check_internal_position,
    check_text,
)

READER = Nest("reader", 1)
RACK_2 = Nest("rack", 2)
STATIONS = {"reader": 1, "rack": 4}


def robot_status(hotel: dict[int, str] | None = None, held: str = "") -> RobotStatus:
    slots = tuple(
        HotelSlotReading(HotelSlot(index), plate, "") for index, plate in (hotel or {1: "", 2: ""}).items()
    )
    return RobotStatus("idle", "", "", 0.0, 0.0, 0.0, slots, held)


# --- manipulator command order ---


def test_manipulator_get_then_put_in_standard_order() -> None:
    sequence = ManipulatorSequence()
    sequence.begin_prepare_for_input(PreparedTransfer(READER, 1, "plate", "P1"))
    assert sequence.phase is ManipulatorPhase.PREPARING_INPUT
    sequence.finish_prepare(success=True)
    transfer = sequence.begin_get(READER)
    assert transfer.labware_id == "P1" and sequence.phase is ManipulatorPhase.GETTING
    sequence.finish_transfer()
    sequence.begin_prepare_for_output(PreparedTransfer(RACK_2, 1))
    sequence.finish_prepare(success=True)
    assert sequence.begin_put(RACK_2).internal_position == 1
    sequence.finish_transfer()
    assert sequence.phase is ManipulatorPhase.IDLE and sequence.transfer is None


@pytest.mark.parametrize("command", ["get", "put"])
def test_manipulator_transfer_without_prepare_is_refused(command: str) -> None:
    sequence = ManipulatorSequence()
    begin = sequence.begin_get if command == "get" else sequence.begin_put
    with pytest.raises(CommandSequenceError, match="first; the robot is idle"):
        begin(READER)
    assert sequence.phase is ManipulatorPhase.IDLE


def test_manipulator_wrong_direction_wrong_place_and_busy_are_refused() -> None:
    sequence = ManipulatorSequence()
    sequence.begin_prepare_for_input(PreparedTransfer(READER, 1))
    with pytest.raises(CommandSequenceError, match="busy preparing for input at reader/1"):
        sequence.begin_get(READER)
    with pytest.raises(CommandSequenceError, match="busy"):
        sequence.begin_motion("Dock")
    sequence.finish_prepare(success=True)
    with pytest.raises(CommandSequenceError, match="PutLabware needs PrepareForOutput first"):
        sequence.begin_put(READER)
    with pytest.raises(CommandSequenceError, match="at rack/2, but PrepareForInput was for reader/1"):
        sequence.begin_get(RACK_2)
    with pytest.raises(CommandSequenceError, match="already prepared for input at reader/1; send GetLabware"):
        sequence.begin_prepare_for_output(PreparedTransfer(RACK_2, 1))
    assert sequence.phase is ManipulatorPhase.PREPARED_FOR_INPUT  # refusals change nothing


def test_manipulator_failed_steps_and_motions_return_to_idle() -> None:
    sequence = ManipulatorSequence()
    sequence.begin_prepare_for_input(PreparedTransfer(READER, 1))
    sequence.finish_prepare(success=False)
    assert sequence.phase is ManipulatorPhase.IDLE
    sequence.begin_prepare_for_input(PreparedTransfer(READER, 1))
    sequence.finish_prepare(success=True)
    sequence.begin_motion("DriveToPointOfInterest")  # voids the preparation
    sequence.finish_motion()
    with pytest.raises(CommandSequenceError):
        sequence.begin_get(READER)


@given(st.lists(st.sampled_from(["in", "out", "get", "put", "ok", "fail", "done"]), max_size=12))
def test_manipulator_transfers_only_follow_a_matching_prepare(commands: list[str]) -> None:
    """Model check: Get/Put start only right after a successful Prepare of the matching direction."""
    sequence = ManipulatorSequence()
    for command in commands:
        before = sequence.phase
        try:
            if command == "in":
                sequence.begin_prepare_for_input(PreparedTransfer(READER, 1))
            elif command == "out":
                sequence.begin_prepare_for_output(PreparedTransfer(READER, 1))
            elif command == "get":
                sequence.begin_get(READER)
                assert before is ManipulatorPhase.PREPARED_FOR_INPUT
            elif command == "put":
                sequence.begin_put(READER)
                assert before is ManipulatorPhase.PREPARED_FOR_OUTPUT
            elif command in ("ok", "fail"):
                if before in (ManipulatorPhase.PREPARING_INPUT, ManipulatorPhase.PREPARING_OUTPUT):
                    sequence.finish_prepare(success=command == "ok")
            elif before in (ManipulatorPhase.GETTING, ManipulatorPhase.PUTTING):
                sequence.finish_transfer()
        except CommandSequenceError:
            assert sequence.phase is before
            if command in ("in", "out"):
                assert before is not ManipulatorPhase.IDLE
            if command == "get":
                assert before is not ManipulatorPhase.PREPARED_FOR_INPUT
            if command == "put":
                assert before is not ManipulatorPhase.PREPARED_FOR_OUTPUT


# --- station command order ---


def test_site_source_and_destination_orders() -> None:
    site = SiteSequence("rack", 4)
    site.prepare_for_output(1, 1, occupied=True)
    assert site.nest(1).phase is NestPhase.PREPARED_FOR_OUTPUT
    site.labware_removed(1)
    site.prepare_for_input(2, 1, "plate", "P7", occupied=False)
    assert site.labware_delivered(2).labware_id == "P7"
    assert site.nest(2).phase is NestPhase.IDLE


def test_site_refuses_out_of_order_and_occupancy_conflicts() -> None:
    site = SiteSequence("rack", 4)
    with pytest.raises(CommandSequenceError, match="LabwareDelivered at rack/1 needs PrepareForInput first"):
        site.labware_delivered(1)
    with pytest.raises(CommandSequenceError, match="LabwareRemoved at rack/1 needs PrepareForOutput first"):
        site.labware_removed(1)
    with pytest.raises(CommandSequenceError, match="nest rack/3 is occupied"):
        site.prepare_for_input(3, 1, "", "", occupied=True)
    with pytest.raises(CommandSequenceError, match="nest rack/3 is empty"):
        site.prepare_for_output(3, 1, occupied=False)
    site.prepare_for_input(3, 1, "", "", occupied=False)
    with pytest.raises(CommandSequenceError, match="LabwareRemoved at rack/3 needs PrepareForOutput"):
        site.labware_removed(3)
    with pytest.raises(CommandSequenceError, match="prepared for input; LabwareDelivered must come"):
        site.prepare_for_output(3, 1, occupied=True)
    assert site.nest(3).phase is NestPhase.PREPARED_FOR_INPUT
    assert site.nest(4).phase is NestPhase.IDLE  # nests are independent


# --- parameters ---


def test_parameter_errors_name_the_problem() -> None:
    assert check_handover("rack", 4, STATIONS) == Nest("rack", 4)
    with pytest.raises(ParameterError, match=r"handover position 'oven'; known positions: rack, reader"):
        check_handover("oven", 1, STATIONS)
    with pytest.raises(ParameterError, match=r"SubPosition 5 is beyond .*'rack'.*\(1..4\)") as caught:
        check_handover("rack", 5, STATIONS)
    assert caught.value.parameter == "HandoverPosition"
    with pytest.raises(ParameterError, match="must not be empty"):
        check_handover("", 1, STATIONS)
    with pytest.raises(ParameterError, match=r"InternalPosition 3 .* 2 internal positions") as caught:
        check_internal_position(3, 2)
    assert caught.value.parameter == "InternalPosition"
    with pytest.raises(ParameterError, match="unknown intermediate action 'shake'; this device offers: none"):
        check_intermediate_actions(["shake"], [])
    assert check_intermediate_actions([], []) == ()
    with pytest.raises(ParameterError, match=f"at most {MAX_TEXT_LENGTH}"):
        check_text("x" * (MAX_TEXT_LENGTH + 1), "LabwareType", allow_empty=True)
    with pytest.raises(ParameterError, match="control characters"):
        check_text("a\nb", "LabwareUniqueID", allow_empty=True)
    assert check_text("", "LabwareUniqueID", allow_empty=True) == ""


# --- inventory ---


def test_the_mirror_takes_the_robot_sides_inventory_and_tells_only_changes() -> None:
    inventory = Inventory()
    heard: list[tuple[str, ...]] = []
    inventory.add_listener(lambda records: heard.append(tuple(r.labware_id for r in records)))
    records = (LabwareRecord("P1", "plate", READER), LabwareRecord("P2", "", HotelSlot(2)))
    inventory.replace(InventorySnapshot(7, records))
    inventory.replace(InventorySnapshot(8, records))  # a new revision of the same records
    assert heard == [("P1", "P2")] and inventory.revision == 8
    assert inventory.in_hotel_slot(2).labware_id == "P2" and inventory.in_hotel_slot(1) is None
    assert inventory.at(READER).labware_id == "P1" and inventory.locate("P3") is None
    inventory.mark_all_unknown()  # the robot side is gone: no sensor vouches for any plate
    assert {r.location for r in inventory.records()} == {UNKNOWN} and len(heard) == 2
