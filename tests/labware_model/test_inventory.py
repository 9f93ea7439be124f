"""The inventory's rules (labware_model.inventory): names from the scheduler, places from presence."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from labware_model.holders import GRIPPER, UNKNOWN, HotelSlot, Nest
from labware_model.inventory import LabwareBook, LabwareRecord, NameTaken, SensedPlate

A1, B1 = Nest("station_a", 1), Nest("station_b", 1)
SLOT1, SLOT2 = HotelSlot(1), HotelSlot(2)
HOLDERS = (A1, B1, SLOT1, SLOT2, GRIPPER)


def test_a_plate_takes_its_label_as_name_until_a_scheduler_names_it() -> None:
    book = LabwareBook()
    assert book.reconcile([SensedPlate(A1, "plate_001", "sbs_96")], HOLDERS)
    assert book.get("plate_001") == LabwareRecord("plate_001", "sbs_96", A1, "plate_001")
    record = book.name_plate(A1, "p1", "", "plate_001")
    assert record is not None and book.get("plate_001") is None
    assert (record.labware_id, record.labware_type, record.location, record.label) == (
        "p1",
        "sbs_96",
        A1,
        "plate_001",
    )
    assert record.note == "its label reads 'plate_001', not 'p1'"


def test_a_transfer_settles_the_named_plate_on_presence_whatever_its_label_reads() -> None:
    book = LabwareBook([LabwareRecord("p1", "", A1, "plate_001")])
    # in the hotel slot the reader reads nothing: presence is what counts
    assert book.settle("p1", (SLOT1, GRIPPER, A1), [SensedPlate(SLOT1)])
    assert book.get("p1").location == SLOT1
    # a failed place: the destination sees nothing, the gripper still holds it
    assert book.settle("p1", (B1, GRIPPER, SLOT1), [SensedPlate(GRIPPER)])
    assert book.get("p1").location == GRIPPER
    assert book.settle("p1", (B1, GRIPPER, SLOT1), [])  # seen nowhere it could be
    assert book.get("p1").location == UNKNOWN


def test_between_transfers_the_book_follows_the_sensors() -> None:
    book = LabwareBook([LabwareRecord("p1", "", SLOT1, "plate_001"), LabwareRecord("p2", "", B1)])
    # p1's label read at station_a/1 (the lab was reset); p2's nest empty; an unread plate in slot 2
    sensed = [SensedPlate(A1, "plate_001"), SensedPlate(SLOT2)]
    assert book.reconcile(sensed, HOLDERS)
    assert book.get("p1").location == A1 and book.get("p2").location == UNKNOWN
    assert book.at(SLOT2) is None  # unread and unnamed: a goal names it
    assert not book.reconcile(sensed, HOLDERS)  # nothing new


def test_an_unread_plate_keeps_the_name_recorded_where_it_stands() -> None:
    book = LabwareBook([LabwareRecord("p1", "", SLOT1, "plate_001")])
    assert not book.reconcile([SensedPlate(SLOT1)], HOLDERS)
    assert book.get("p1").location == SLOT1
    # but a label read there that is another plate's means another plate
    book.reconcile([SensedPlate(SLOT1, "plate_009")], HOLDERS)
    assert book.get("p1").location == UNKNOWN and book.get("plate_009").location == SLOT1


def test_a_name_names_one_plate() -> None:
    book = LabwareBook([LabwareRecord("p1", "", SLOT1), LabwareRecord("lost", "", UNKNOWN)])
    with pytest.raises(NameTaken, match="'p1' is at hotel slot 1"):
        book.name_plate(A1, "p1", "", "")
    assert book.name_plate(A1, "lost", "", "").location == A1  # a lost plate found again
    assert book.name_plate(SLOT1, "p1", "", "").location == SLOT1  # the plate it names
    assert book.name_plate(B1, "", "", "") is None  # no name, no label: stays unnamed


def test_the_file_form_reads_back_and_refuses_other_text() -> None:
    book = LabwareBook([LabwareRecord("p1", "t", SLOT1, "plate_001"), LabwareRecord("p2", "", UNKNOWN)])
    again = LabwareBook.from_json(book.to_json())
    fields = [(r.labware_id, r.labware_type, r.location, r.label) for r in again.records()]
    assert fields == [(r.labware_id, r.labware_type, r.location, r.label) for r in book.records()]
    assert again.get("p1").note  # the note follows from the label and the name
    for text in ("{", "[{}]", '[{"labware_id": "x", "labware_type": "", "location": "shelf"}]'):
        with pytest.raises(ValueError):
            LabwareBook.from_json(text)


plates = st.lists(
    st.tuples(st.sampled_from(HOLDERS), st.sampled_from(["", "L1", "L2", "L3"])),
    unique_by=lambda plate: plate[0],
    max_size=4,
)


@given(st.lists(st.tuples(plates, st.sampled_from(["", "n1", "n2"]), st.sampled_from(HOLDERS)), max_size=8))
def test_whatever_the_sensors_say_a_holder_holds_at_most_one_named_plate(steps) -> None:  # noqa: ANN001
    book = LabwareBook()
    for seen, name, holder in steps:
        sensed = [SensedPlate(where, label) for where, label in seen]
        book.reconcile(sensed, HOLDERS)
        try:
            book.name_plate(holder, name, "", "")
        except NameTaken:
            pass
        book.settle(name, (holder,), sensed)
        placed = [record.location for record in book.records() if record.location != UNKNOWN]
        assert len(placed) == len(set(placed))


def test_a_holder_without_a_sensor_keeps_the_plate_its_checked_steps_put_there() -> None:
    """A hotel without sensors: a delivered plate is where the transfer put it; one that no grasp
    touched stays where it lay; a sensor that sees it elsewhere still wins."""
    book = LabwareBook([LabwareRecord("p1", "", A1, "")])
    assert book.settle("p1", (SLOT1, GRIPPER, A1), [], unsensed=SLOT1)
    assert book.get("p1").location == SLOT1
    assert not book.settle("p1", (B1, GRIPPER, SLOT1), [], unsensed=SLOT1)  # refused before the grasp
    assert book.get("p1").location == SLOT1
    assert book.settle("p1", (B1, GRIPPER, SLOT1), [SensedPlate(B1)], unsensed=SLOT1)
    assert book.get("p1").location == B1
