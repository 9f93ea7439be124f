"""The plans' post-conditions and the retreat after a failure, without ROS processes (milliseconds).

Beside the real-process tests (test_ros_transfer.py, test_sequencer_bounds.py), which inject each
fault into the running simulation: these pin which step checks which sensor with which error,
what the error says the sensor saw, and how the arm backs out afterwards.
"""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import pytest
from labware_interfaces.msg import ErrorCodes, HotelSlot, NestState, RobotState, StationStates

from labware_model.holders import GRIPPER, Nest
from labware_model.holders import HotelSlot as Slot
from labware_model.workcell import STOCK_SENSORS, StationDescription, WorkcellDescription
from tiago_sim.sequencer.plans import Expect, TaskRefused, get_plan, is_inspection, put_plan, retreat_steps
from tiago_sim.sequencer.postconditions import topic_of, unmet

WORKCELL = WorkcellDescription((StationDescription("station_a", 2, "station_a_work"),), 2, (), "dock")
A1 = Nest("station_a", 1)


UNREAD = "?"  # in `hotel`: a plate in the slot whose label the reader could not read


def robot(
    hotel: dict[int, str] | None = None, held: str = "", poi: str = "station_a_work", holding: bool = False
) -> RobotState:
    slots = [
        HotelSlot(index=i, labware_id=plate.strip(UNREAD), occupied=bool(plate))
        for i, plate in (hotel or {1: "", 2: ""}).items()
    ]
    return RobotState(
        state="idle", current_poi=poi, hotel=slots, held_labware_id=held, holding=holding or bool(held)
    )


def stations(plate: str = "", occupied: bool | None = None) -> StationStates:
    full = bool(plate) if occupied is None else occupied
    return StationStates(
        nests=[
            NestState(station="station_a", sub_position=1, occupied=full, labware_id=plate),
            NestState(station="station_a", sub_position=2, occupied=False, labware_id=""),
        ]
    )


def goal() -> SimpleNamespace:
    return SimpleNamespace(handover_position="station_a", sub_position=1, internal_position=1)


def checks(plan: list) -> list[tuple[str, object, str]]:
    return [(step.phase, step.post.holder, step.post.code) for step in plan if step.post is not None]


STOCK = replace(WORKCELL, sensors=STOCK_SENSORS)


def book(**plates: str):
    """An inventory lookup recording plates at "slot1", "slot2", "a1" (the name, or "" unnamed)."""
    places = {Slot(1): plates.get("slot1"), Slot(2): plates.get("slot2"), A1: plates.get("a1")}
    return lambda holder: places.get(holder)


def test_without_sensors_a_get_is_checked_by_the_fingers_alone() -> None:
    """No nest sensor: the grasp finds out whether the source holds a plate; no hotel sensor: the
    plate held down in the pocket until the release is the check of the stowing."""
    plan = get_plan(goal(), STOCK, robot(hotel={}), None, "right", book())
    assert [step.phase for step in plan if step.expect_holding] == ["grasp"]
    assert checks(plan) == [
        ("lifting", GRIPPER, ErrorCodes.PLATE_SLIPPED),
        ("into hotel", GRIPPER, ErrorCodes.PLATE_SLIPPED),
    ]
    assert not any(is_inspection(step) for step in plan)


def test_without_sensors_a_put_looks_into_the_nest_before_and_after() -> None:
    plan = put_plan(goal(), STOCK, robot(hotel={}), None, "right", book(slot1="P1"))
    assert checks(plan) == [
        ("checking the nest is free", A1, ErrorCodes.NEST_OCCUPIED),
        ("lifting", GRIPPER, ErrorCodes.PLATE_SLIPPED),
        ("placing", GRIPPER, ErrorCodes.PLATE_SLIPPED),
        ("checking the plate is in the nest", A1, ErrorCodes.PLACE_FAILED),
    ]
    looks = [step for step in plan if is_inspection(step)]
    assert [step.post.empty for step in looks] == [True, False]
    assert plan[1] is looks[0], "the nest is looked into before the arm moves"
    assert plan[-1] is looks[1] and plan[-2].goal["motion_name"] == "Tuck", "and once the arm is out of view"


@pytest.mark.parametrize(
    ("make_plan", "plates", "code", "words"),
    [
        (
            get_plan,
            {"slot1": "P9"},
            ErrorCodes.SLOT_OCCUPIED,
            "hotel slot 1 already holds P9 (by the inventory",
        ),
        (put_plan, {}, ErrorCodes.SLOT_EMPTY, "hotel slot 1 holds no plate (by the inventory"),
        (put_plan, {"slot1": "P1", "a1": ""}, ErrorCodes.NEST_OCCUPIED, "holds a plate (by the inventory"),
    ],
)
def test_without_sensors_the_inventory_stands_in_before_anything_moves(
    make_plan, plates, code, words
) -> None:
    with pytest.raises(TaskRefused) as refused:
        make_plan(goal(), STOCK, robot(hotel={}), None, "right", book(**plates))
    assert refused.value.code == code
    assert words in refused.value.message


def test_get_checks_the_gripper_while_carrying_and_the_hotel_slot_after_stowing() -> None:
    plan = get_plan(goal(), WORKCELL, robot(), stations("P1"), "right")
    assert [step.phase for step in plan if step.expect_holding] == ["grasp"]
    assert checks(plan) == [
        ("lifting", GRIPPER, ErrorCodes.PLATE_SLIPPED),
        ("into hotel", GRIPPER, ErrorCodes.PLATE_SLIPPED),
        ("release", Slot(1), ErrorCodes.PLACE_FAILED),
        ("arm tucked", Slot(1), ErrorCodes.PLATE_SLIPPED),
    ]
    assert plan[-1].phase == "arm tucked", "the last check is on the task's last step"


def test_put_checks_the_hotel_before_the_grasp_and_the_nest_after_the_release() -> None:
    plan = put_plan(goal(), WORKCELL, robot({1: "P1", 2: ""}), stations(), "right")
    assert checks(plan) == [
        ("final approach", Slot(1), ErrorCodes.PLATE_SLIPPED),
        ("lifting", GRIPPER, ErrorCodes.PLATE_SLIPPED),
        ("placing", GRIPPER, ErrorCodes.PLATE_SLIPPED),
        ("release", A1, ErrorCodes.PLACE_FAILED),
        ("arm tucked", A1, ErrorCodes.PLACE_FAILED),
    ]


@pytest.mark.parametrize(
    ("expect", "robot_state", "station_states", "seen"),
    [
        (Expect(GRIPPER, "X"), robot(held="P1"), stations(), ""),
        (Expect(GRIPPER, "X"), robot(), stations(), "the gripper holds nothing"),
        (Expect(GRIPPER, "X"), robot(held="P7"), stations(), "the gripper holds P7, not P1"),
        (Expect(GRIPPER, "X"), robot(holding=True), stations(), ""),  # held, its label unread
        (Expect(Slot(1), "X"), robot({1: UNREAD, 2: ""}), stations(), ""),  # stowed, label unread
        (
            Expect(Slot(1), "X"),
            robot({1: "P7", 2: ""}),
            stations(),
            "the sensor of hotel slot 1 sees P7, not P1",
        ),
        (Expect(Slot(1), "X"), robot({1: "P1", 2: ""}), stations(), ""),
        (
            Expect(Slot(1), "X"),
            robot({1: "", 2: "P1"}),
            stations(),
            "the sensor of hotel slot 1 sees no plate",
        ),
        (Expect(A1, "X"), robot(), stations("P1"), ""),
        (Expect(A1, "X"), robot(), stations("", occupied=True), ""),  # a sensor that reads no ids
        (Expect(A1, "X"), robot(), stations(), "the sensor of nest station_a/1 sees no plate"),
        (Expect(A1, "X"), robot(), stations("P7"), "the sensor of nest station_a/1 sees P7, not P1"),
    ],
)
def test_a_post_condition_says_what_the_sensor_saw(
    expect: Expect, robot_state: RobotState, station_states: StationStates, seen: str
) -> None:
    assert unmet(expect, "P1", robot_state, station_states) == seen


def test_a_plate_whose_label_was_not_read_still_fills_its_hotel_slot() -> None:
    with pytest.raises(TaskRefused) as refused:
        get_plan(goal(), WORKCELL, robot({1: UNREAD, 2: ""}), stations("P1"), "right")
    assert refused.value.code == ErrorCodes.SLOT_OCCUPIED
    assert "could not read" in str(refused.value)
    assert put_plan(goal(), WORKCELL, robot({1: UNREAD, 2: ""}), stations(), "right")  # not SLOT_EMPTY
    with pytest.raises(TaskRefused) as refused:
        put_plan(goal(), WORKCELL, robot(), stations(), "right")
    assert refused.value.code == ErrorCodes.SLOT_EMPTY


def test_nest_checks_read_the_station_topic_and_the_others_the_robots() -> None:
    assert [topic_of(Expect(holder, "X")) for holder in (GRIPPER, Slot(1), A1)] == [
        "robot",
        "robot",
        "stations",
    ]


def retreat_after(plan: list, phase: str) -> list[tuple[str, str]]:
    index = next(i for i, step in enumerate(plan) if step.phase == phase)
    return [
        (step.action, step.goal.get("motion_name") or step.goal.get("target") or step.goal.get("command"))
        for step in retreat_steps(plan, index)
    ]


def test_the_arm_backs_out_of_the_nest_or_pocket_it_stands_in_and_tucks() -> None:
    get = get_plan(goal(), WORKCELL, robot(), stations("P1"), "right")
    put = put_plan(goal(), WORKCELL, robot({1: "P1", 2: ""}), stations(), "right")
    open_, tuck = ("gripper", "open"), ("play_motion", "Tuck")
    assert retreat_after(get, "grasp") == [open_, ("marker_motion", "site_approach"), tuck]
    assert retreat_after(get, "lifting") == [open_, tuck]  # already above the nest
    assert retreat_after(get, "into hotel") == [open_, ("play_motion", "NestApproach"), tuck]
    assert retreat_after(get, "arm tucked") == []
    assert retreat_after(put, "final approach") == []  # the arm has not moved yet
    assert retreat_after(put, "grasp") == [open_, ("play_motion", "NestApproach"), tuck]
    assert retreat_after(put, "release") == [open_, ("marker_motion", "site_approach"), tuck]
