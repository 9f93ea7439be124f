"""RobotController and StationController against the in-memory FakeRobot: no DDS, milliseconds.

Beside the real-DDS tests (test_sila_controller.py), which stay: these cover the paths that are
slow or hard to provoke on a real robot side - refusals before any goal, a step that times out,
settling the inventory after every kind of outcome, the supervisor's abort, and progress across
the goals of one command. Waits are tiny (tens of ms), so all of them run in well under a second.
"""

from __future__ import annotations

import inspect
import threading
import time
from collections.abc import Callable
from dataclasses import replace

import pytest

from labware_model.holders import GRIPPER, UNKNOWN, HotelSlot, Nest
from labware_model.workcell import StationDescription, WorkcellDescription
from ros_bridge.robot_link import RobotLink
from sila_labware.device.errors import CommandSequenceError, MotionFailed, ParameterError, TransferFailed
from sila_labware.device.robot_backend import RobotBackend, StationBackend
from sila_labware.device.robot_controller import ControllerWaits, RobotController
from sila_labware.device.station_controller import StationController
from tests.helpers.fake_robot import (
    FakeRobot,
    ends_when_cancelled,
    fail,
    nest,
    never_ends,
    rejected,
    result_with_labware_id,
    robot_state,
    succeed,
    unsendable,
)

WORKCELL = WorkcellDescription(
    stations=(StationDescription("reader", 1, "reader_poi"), StationDescription("rack", 4, "rack_poi")),
    hotel_slots=2,
    pois=("reader_poi", "rack_poi", "dock_approach"),
    dock_poi="dock_approach",
)
STEP_TIMEOUT_S = 0.05
TINY_WAITS = ControllerWaits(accept_s=0.05, cancel_s=0.05, state_report_s=0.02, settle_s=0.02)
SUPERVISOR_REASON = "robot side lost: sim ended (exit code -9); restarting it"


def controller_on(fake: FakeRobot, step_timeout_s: float = STEP_TIMEOUT_S) -> RobotController:
    return RobotController(fake, WORKCELL, step_timeout_s=step_timeout_s, waits=TINY_WAITS)


def at_reader_with_plate(plate: str = "P1") -> FakeRobot:
    """The robot idle at the reader's POI, the reader's nest holding `plate`."""
    return FakeRobot(robot_state(poi="reader_poi"), (nest("reader", 1, plate), nest("rack", 2)))


def carrying_to_rack(plate: str = "P1") -> FakeRobot:
    """The robot idle at the rack's POI with `plate` in hotel slot 1; rack nest 2 empty."""
    return FakeRobot(
        robot_state(poi="rack_poi", hotel={1: plate, 2: ""}), (nest("reader", 1), nest("rack", 2))
    )


def run_in_thread(call: Callable[[], object]) -> tuple[threading.Thread, list[BaseException]]:
    """Run a blocking command as a SiLA handler thread would; what it raises lands in the list."""
    raised: list[BaseException] = []

    def handler() -> None:
        try:
            call()
        except Exception as error:  # noqa: BLE001 - handed to the test
            raised.append(error)

    thread = threading.Thread(target=handler, name="sila-handler")
    thread.start()
    return thread, raised


def until_true(attempt: Callable[[], bool], timeout_s: float = 1.0) -> None:
    deadline = time.monotonic() + timeout_s
    while not attempt():
        assert time.monotonic() < deadline, "gave up waiting"
        time.sleep(0.001)


# --- the back-end protocol ---


@pytest.mark.parametrize("backend", [RobotLink, FakeRobot], ids=["RobotLink", "FakeRobot"])
def test_the_link_and_the_fake_have_the_protocols_signatures(backend: type) -> None:
    members = [name for name in dir(RobotBackend) if not name.startswith("_")]
    assert len(members) == 13, members
    for name in members:
        assert inspect.signature(getattr(backend, name)) == inspect.signature(getattr(RobotBackend, name)), (
            name
        )


def test_the_fake_is_a_robot_backend_and_a_station_backend() -> None:
    fake = FakeRobot()
    assert isinstance(fake, RobotBackend) and isinstance(fake, StationBackend)


# --- refusals: before any goal ---


@pytest.mark.parametrize(
    ("position", "sub_position", "message"),
    [
        ("attic", 1, "unknown handover position 'attic'; known positions: rack, reader"),
        ("reader", 2, "SubPosition 2 is beyond handover position 'reader', which has 1 sub-position"),
    ],
)
def test_a_handover_the_workcell_lacks_is_refused_before_any_goal(
    position: str, sub_position: int, message: str
) -> None:
    fake = FakeRobot(robot_state(state="docked"))
    controller = controller_on(fake)
    with pytest.raises(ParameterError) as refused:
        controller.prepare_for_input(position, sub_position, 1, "plate_96", "P1")
    assert refused.value.parameter == "HandoverPosition" and message in refused.value.message
    assert fake.sent == []


def test_an_occupied_hotel_slot_refuses_prepare_for_input() -> None:
    fake = FakeRobot(robot_state(hotel={1: "P9", 2: ""}), (nest("reader", 1, "P1"),))
    controller = controller_on(fake)
    with pytest.raises(CommandSequenceError, match="internal position 1 already holds labware 'P9'"):
        controller.prepare_for_input("reader", 1, 1, "plate_96", "P1")
    assert fake.sent == [] and controller.sequence.phase.value == "idle"


def test_an_occupied_destination_nest_refuses_prepare_for_output() -> None:
    fake = FakeRobot(robot_state(hotel={1: "P1", 2: ""}), (nest("rack", 2, "P7"),))
    controller = controller_on(fake)
    with pytest.raises(CommandSequenceError, match=r"destination rack/2 is occupied \(holds P7\)"):
        controller.prepare_for_output("rack", 2, 1)
    assert fake.sent == []


def test_an_empty_hotel_slot_refuses_prepare_for_output() -> None:
    fake = FakeRobot(robot_state(), (nest("rack", 2),))
    with pytest.raises(CommandSequenceError, match="internal position 2 holds no labware"):
        controller_on(fake).prepare_for_output("rack", 2, 2)
    assert fake.sent == []


def test_transfers_out_of_protocol_order_are_refused() -> None:
    fake = at_reader_with_plate()
    controller = controller_on(fake)
    with pytest.raises(CommandSequenceError, match="first; the robot is idle"):
        controller.get_labware("reader", 1, [])
    controller.prepare_for_input("reader", 1, 1, "plate_96", "P1")  # at the POI already: no goal
    with pytest.raises(CommandSequenceError):
        controller.put_labware("reader", 1, [])
    assert fake.sent == []


def test_driving_while_docked_or_to_an_unknown_poi_is_refused() -> None:
    fake = FakeRobot(robot_state(state="docked"))
    controller = controller_on(fake)
    with pytest.raises(MotionFailed) as docked:
        controller.drive_to_poi("rack_poi")
    assert docked.value.error_code == "DOCKED"
    with pytest.raises(ParameterError) as unknown:
        controller.drive_to_poi("attic")
    assert unknown.value.parameter == "PointOfInterest"
    assert "known: reader_poi, rack_poi" in unknown.value.message
    assert fake.sent == []


def test_a_busy_robot_refuses_a_second_command_while_a_goal_runs() -> None:
    fake = FakeRobot(robot_state(poi="rack_poi"), (nest("reader", 1, "P1"),))
    controller = controller_on(fake)
    refused: list[Exception] = []

    def dock_meanwhile() -> None:
        try:
            controller.dock()
        except CommandSequenceError as error:
            refused.append(error)

    fake.script("navigate_to_poi", succeed(while_running=dock_meanwhile))
    controller.prepare_for_input("reader", 1, 1, "plate_96", "P1")
    assert [str(error) for error in refused] == [
        "Dock refused: the robot is busy preparing for input at reader/1"
    ]
    assert fake.actions_sent() == ["navigate_to_poi"]
    assert controller.sequence.phase.value == "prepared for input"


# --- a step past its timeout, and goals that never get going ---


def test_a_step_past_its_timeout_is_cancelled_and_reports_the_robots_answer() -> None:
    fake = FakeRobot(robot_state(poi="reader_poi"))
    fake.script("navigate_to_poi", ends_when_cancelled(feedback=(0.1, 0.3)))
    controller = controller_on(fake)
    reports: list[float] = []
    with pytest.raises(MotionFailed) as failed:
        controller.drive_to_poi("rack_poi", report=lambda fraction, _remaining_s: reports.append(fraction))
    assert failed.value.error_code == "CANCELED" and "cancelled after" in failed.value.message
    assert len(fake.sent[0].cancel_requests) == 1
    assert reports == [0.1, 0.3]
    assert controller.sequence.phase.value == "idle"


def test_a_step_that_ignores_its_cancel_fails_with_timeout() -> None:
    fake = FakeRobot(robot_state(poi="reader_poi"))
    fake.script("navigate_to_poi", never_ends())
    controller = controller_on(fake)
    with pytest.raises(MotionFailed) as failed:
        controller.drive_to_poi("rack_poi")
    assert failed.value.error_code == "TIMEOUT"
    assert "DriveToPointOfInterest: no result within" in failed.value.message
    assert len(fake.sent[0].cancel_requests) == 1
    assert controller.stop_motion() is False, "the command ended; nothing is left running"


def test_a_transfer_past_its_timeout_is_cancelled_and_settles_where_the_plate_is() -> None:
    fake = at_reader_with_plate()
    controller = controller_on(fake)
    controller.prepare_for_input("reader", 1, 1, "plate_96", "P1")
    fake.script("get_labware", ends_when_cancelled(feedback=(0.4,)))
    with pytest.raises(TransferFailed) as failed:
        controller.get_labware("reader", 1, [])
    assert failed.value.error_code == "CANCELED"
    assert controller.inventory.locate("P1").location == Nest("reader", 1)
    assert controller.sequence.phase.value == "idle"


@pytest.mark.parametrize(
    ("script", "error_code", "says"),
    [(rejected(), "GoalRejected", "rejected the goal"), (unsendable(), "BridgeError", "could not be sent")],
)
def test_a_goal_rejected_or_not_sent_becomes_the_commands_failure(script, error_code: str, says: str) -> None:
    fake = FakeRobot(robot_state(state="docked"))
    fake.script("undock", script)
    with pytest.raises(MotionFailed) as failed:
        controller_on(fake).undock()
    assert failed.value.error_code == error_code and says in failed.value.message


# --- settling the inventory after success and failure ---


def test_a_successful_get_puts_the_plate_in_the_hotel_slot() -> None:
    fake = at_reader_with_plate()
    controller = controller_on(fake)
    controller.prepare_for_input("reader", 1, 2, "plate_96", "P1")
    assert controller.get_labware("reader", 1, []) == "P1"
    record = controller.inventory.locate("P1")
    assert record.location == HotelSlot(2) and record.labware_type == "plate_96"
    assert fake.sent[0].argument.hotel_slot == HotelSlot(2)


def test_a_get_without_a_plate_id_records_the_id_the_robot_read() -> None:
    fake = at_reader_with_plate("P5")
    controller = controller_on(fake)
    controller.prepare_for_input("reader", 1, 1, "", "")
    fake.script("get_labware", succeed(result=result_with_labware_id("P5")))
    assert controller.get_labware("reader", 1, []) == "P5"
    assert controller.inventory.locate("P5").location == HotelSlot(1)


def test_a_failed_get_with_the_plate_in_the_gripper_records_the_gripper() -> None:
    fake = at_reader_with_plate()
    controller = controller_on(fake)
    controller.prepare_for_input("reader", 1, 1, "plate_96", "P1")
    fake.script(
        "get_labware",
        fail(
            "PLATE_SLIPPED",
            "the plate slipped while stowing",
            robot_after=robot_state(poi="reader_poi", held="P1"),
            nests_after=(nest("reader", 1),),
        ),
    )
    with pytest.raises(TransferFailed) as failed:
        controller.get_labware("reader", 1, [])
    assert failed.value.error_code == "PLATE_SLIPPED"
    assert failed.value.message == "GetLabware failed (PLATE_SLIPPED): the plate slipped while stowing"
    assert controller.inventory.locate("P1").location == GRIPPER


def test_a_failed_get_that_never_touched_the_plate_leaves_it_in_the_nest() -> None:
    fake = at_reader_with_plate()
    controller = controller_on(fake)
    controller.prepare_for_input("reader", 1, 1, "plate_96", "P1")
    fake.script("get_labware", fail("MARKER_NOT_FOUND"))
    with pytest.raises(TransferFailed):
        controller.get_labware("reader", 1, [])
    assert controller.inventory.locate("P1").location == Nest("reader", 1)


def test_a_successful_put_puts_the_plate_in_the_nest() -> None:
    fake = carrying_to_rack()
    controller = controller_on(fake)
    controller.prepare_for_output("rack", 2, 1)
    assert controller.put_labware("rack", 2, []) == "P1"
    assert controller.inventory.locate("P1").location == Nest("rack", 2)


def test_a_failed_put_that_dropped_the_plate_records_it_lost() -> None:
    fake = carrying_to_rack()
    controller = controller_on(fake)
    controller.prepare_for_output("rack", 2, 1)
    fake.script("put_labware", fail("PLACEMENT_FAILED", robot_after=robot_state(poi="rack_poi")))
    with pytest.raises(TransferFailed) as failed:
        controller.put_labware("rack", 2, [])
    assert failed.value.error_code == "PLACEMENT_FAILED"
    assert controller.inventory.locate("P1").location == UNKNOWN


# --- the scheduler's ids are names; the sensors say where ---


def test_a_scheduler_id_names_the_plate_whatever_its_label_reads() -> None:
    fake = at_reader_with_plate("plate_001")  # the plate's label, which the scheduler does not know
    controller = controller_on(fake)
    controller.prepare_for_input("reader", 1, 2, "plate_96", "p1")
    assert controller.get_labware("reader", 1, []) == "p1"
    record = controller.inventory.locate("p1")
    assert (record.location, record.label) == (HotelSlot(2), "plate_001")
    assert record.note == "its label reads 'plate_001', not 'p1'"
    assert controller.inventory.locate("plate_001") is None, "one plate, one name"
    fake.set_robot_status(replace(fake.robot_status(), current_poi="rack_poi"))
    controller.prepare_for_output("rack", 2, 2)
    assert controller.put_labware("rack", 2, []) == "p1"
    assert controller.inventory.locate("p1").location == Nest("rack", 2)


def test_an_id_aboard_or_at_another_nest_is_refused_at_prepare_for_input() -> None:
    fake = at_reader_with_plate("plate_001")
    controller = controller_on(fake)
    controller.prepare_for_input("reader", 1, 1, "", "p1")
    controller.get_labware("reader", 1, [])
    fake.set_nests((nest("reader", 1, "plate_002"), nest("rack", 2)))
    with pytest.raises(CommandSequenceError, match="labware 'p1' is already aboard, not at reader/1"):
        controller.prepare_for_input("reader", 1, 2, "", "p1")
    assert fake.actions_sent() == ["get_labware"], "a refusal moves nothing"
    controller.prepare_for_input("reader", 1, 2, "", "p2")  # another name is fine


# --- a success the sensors do not show is a failure ---


def test_a_get_reported_done_with_the_plate_not_in_its_slot_fails_and_records_what_the_sensors_say() -> None:
    fake = at_reader_with_plate()
    controller = controller_on(fake)
    controller.prepare_for_input("reader", 1, 1, "plate_96", "P1")
    # the robot side says done, but the hotel is empty and the plate is still between the fingers
    fake.script("get_labware", succeed(robot_after=robot_state(poi="reader_poi", held="P1")))
    with pytest.raises(TransferFailed) as failed:
        controller.get_labware("reader", 1, [])
    assert failed.value.error_code == "PLATE_SLIPPED"
    assert failed.value.message == (
        "GetLabware failed (PLATE_SLIPPED): the robot side reported success, but the sensor of "
        "hotel slot 1 sees no plate; the inventory has it at gripper"
    )
    assert controller.inventory.locate("P1").location == GRIPPER
    assert controller.sequence.phase.value == "idle"


def test_a_put_reported_done_with_an_empty_nest_fails_and_records_the_plate_lost() -> None:
    fake = carrying_to_rack()
    controller = controller_on(fake)
    controller.prepare_for_output("rack", 2, 1)
    fake.script(
        "put_labware",
        succeed(robot_after=robot_state(poi="rack_poi"), nests_after=(nest("reader", 1), nest("rack", 2))),
    )
    with pytest.raises(TransferFailed) as failed:
        controller.put_labware("rack", 2, [])
    assert failed.value.error_code == "PLACE_FAILED"
    assert failed.value.message == (
        "PutLabware failed (PLACE_FAILED): the robot side reported success, but the sensor of "
        "rack/2 sees no plate"
    )
    assert controller.inventory.locate("P1").location == UNKNOWN


# --- stop and the supervisor's abort ---


def test_the_supervisors_abort_ends_a_waiting_transfer_with_its_defined_error() -> None:
    fake = at_reader_with_plate()
    controller = controller_on(fake, step_timeout_s=5.0)
    controller.prepare_for_input("reader", 1, 1, "plate_96", "P1")
    assert controller.abort_active_goal(SUPERVISOR_REASON) is False, "nothing runs yet"
    fake.script("get_labware", never_ends(feedback=(0.3,)))
    started = time.monotonic()
    handler, raised = run_in_thread(lambda: controller.get_labware("reader", 1, []))
    until_true(lambda: controller.abort_active_goal(SUPERVISOR_REASON))  # as the supervisor thread does
    handler.join(1.0)
    assert time.monotonic() - started < 1.0, "the abort must end the wait, not the step timeout"
    (failure,) = raised
    assert isinstance(failure, TransferFailed) and failure.error_code == "GoalAbandoned"
    assert SUPERVISOR_REASON in failure.message
    assert fake.sent[0].cancel_requests == [], "nothing is sent to a robot side that is gone"
    assert controller.sequence.phase.value == "idle"
    assert controller.inventory.locate("P1").location == Nest("reader", 1)


def test_stop_motion_cancels_the_running_goal() -> None:
    fake = FakeRobot(robot_state(poi="reader_poi"))
    fake.script("navigate_to_poi", ends_when_cancelled())
    controller = controller_on(fake, step_timeout_s=5.0)
    handler, raised = run_in_thread(lambda: controller.drive_to_poi("rack_poi"))
    until_true(controller.stop_motion)
    handler.join(1.0)
    (failure,) = raised
    assert isinstance(failure, MotionFailed) and failure.error_code == "CANCELED"


# --- progress across the goals of one command ---


def test_progress_rises_through_undock_and_drive_and_ends_at_one() -> None:
    fake = FakeRobot(robot_state(state="docked"), (nest("reader", 1, "P1"),))
    fake.script("undock", succeed(feedback=(0.5, 1.0)))
    fake.script("navigate_to_poi", succeed(feedback=(0.0, 0.25, 0.1, 0.75)))
    controller = controller_on(fake)
    reports: list[tuple[float, float]] = []
    controller.prepare_for_input(
        "reader", 1, 1, "plate_96", "P1", report=lambda *report: reports.append(report)
    )
    assert fake.actions_sent() == ["undock", "navigate_to_poi"]
    # undock covers 0..0.2: 0.5 -> 0.1, 1.0 -> 0.2, its success 0.2; the drive covers 0.2..1:
    # 0 -> 0.2, 0.25 -> 0.4, 0.1 is below the drive's 0.25 (the goal keeps 0.25 -> 0.4), 0.75 -> 0.8,
    # its success 1.0; then the wait for the state report (1.0, with that wait's bound left); the
    # end reports 1 with nothing left.
    assert [round(fraction, 9) for fraction, _ in reports] == [
        0.1,
        0.2,
        0.2,
        0.2,
        0.4,
        0.4,
        0.8,
        1.0,
        1.0,
        1.0,
    ]
    assert reports[-1] == (1.0, 0.0)


# --- the station's digital twin on the same fake ---


def test_the_station_refuses_and_settles_from_its_nest_sensor() -> None:
    fake = FakeRobot(nests=(nest("rack", 2, "P7"),))
    station = StationController(fake, StationDescription("rack", 4, "rack_poi"), settle_timeout_s=0.02)
    with pytest.raises(CommandSequenceError):
        station.prepare_for_input("rack", 2, 1, "plate_96", "P1")  # the sensor sees P7
    station.prepare_for_output("rack", 2, 1)
    with pytest.raises(CommandSequenceError, match="still sees a plate after"):
        station.labware_removed("rack", 2)
    station.settle_timeout_s = 30.0  # a bound for a loaded machine: the wait ends when the sensor clears
    threading.Timer(0.05, lambda: fake.set_nests((nest("rack", 2),))).start()
    station.labware_removed("rack", 2)  # the sensor clears while the station waits
    assert station.sequence.nest(2).phase.value == "idle"
