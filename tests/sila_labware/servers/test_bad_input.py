"""Bad input everywhere: property-based tests over every command and parameter of every server.

One running stack (real sim node, sequencer, bridge, SiLA servers over gRPC) serves the whole
module. Hypothesis draws strings of any length and content (empty, > 255 characters, unicode,
control characters), indices at and past every bound (0, negative, int64 extremes), unknown
names, and commands in the wrong order. Every drawn call must be refused before any motion, so
the inputs are filtered to those the robot must refuse; a call that is accepted is a failure too.

What may come back: a DefinedExecutionError of the command, or a ValidationError (raised by the
server naming the parameter, or by the sila2 client itself for a constraint of the feature
definition). Never an UndefinedExecutionError, another exception, or no answer within the
per-call deadline. After every call the server must still answer; after every command's run the
inventory, the nest sensors and the robot state must be as before.

The inputs tried are counted per command; the tally is printed at the end of the module (run
with -s) and written as JSON to $BAD_INPUT_REPORT when set.
"""

from __future__ import annotations

import concurrent.futures
import json
import os
import sys
from collections import Counter
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st
from sila2.framework import DefinedExecutionError, ValidationError

from sila_labware.deployment.stack import Deployment
from tests.helpers.sila_stack import start_stack
from tests.helpers.transfer_steps import Cell, finish

CALL_DEADLINE_S = 15.0
MAX_TEXT_LENGTH = 255
INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1
STATIONS = {"station_a": 2, "station_b": 2}  # the default world: two nests each
HOTEL_SLOTS = 2
POINTS_OF_INTEREST = ("dock_approach", "lab_centre", "station_a_work", "station_b_work")
PLATE = "plate_001"  # on station_a/1 in the default world; station_b's nests are empty

EXAMPLES = settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    database=None,
    # The stack is module-wide; `unchanged` is checked once around all examples of a test.
    suppress_health_check=[
        HealthCheck.too_slow,
        HealthCheck.filter_too_much,
        HealthCheck.function_scoped_fixture,
    ],
)

# --- what to draw -------------------------------------------------------------------------------

# Any Unicode scalar value (surrogates cannot be sent as UTF-8, so no client could send them).
characters = st.characters(exclude_categories=["Cs"])
notable_strings = st.sampled_from(
    [
        "",
        " ",
        "station_a ",
        "STATION_A",
        "station_c",
        "station_a/1",
        "station_a\x00",
        "\t",
        "a\nb",
        "\x1b[31m",
        "Straße",
        "站点",
        "🧪" * 200,
        "x" * MAX_TEXT_LENGTH,
        "x" * (MAX_TEXT_LENGTH + 1),
        "x" * 10_000,
        "'; DROP TABLE labware; --",
        "../../etc/passwd",
        "%s%s%n",
        PLATE,
    ]
)
any_text = st.one_of(
    notable_strings,
    st.text(characters, max_size=40),
    st.text(characters, min_size=MAX_TEXT_LENGTH - 2, max_size=MAX_TEXT_LENGTH + 60),
    st.text(st.characters(max_codepoint=31), min_size=1, max_size=5),
)
known_station = st.sampled_from(sorted(STATIONS))
notable_indices = st.sampled_from([0, 1, 2, 3, -1, 2**31, -(2**31), INT64_MAX, INT64_MIN])
any_index = st.one_of(notable_indices, st.integers(INT64_MIN, INT64_MAX), st.integers(-3, 5))
# Valid values about half of the time, so that a call often has exactly one bad parameter (or none,
# where only the protocol order refuses it) and each check is reached on its own.
station_name = st.one_of(known_station, any_text)
index = st.one_of(st.sampled_from([1, 2]), any_index)
free_text = st.one_of(st.sampled_from(["", PLATE, "sbs_microplate_96"]), any_text)
action_list = st.one_of(
    st.just([]),
    st.lists(any_text, min_size=1, max_size=3),
    st.just(["org.silastandard/core/SiLAService/v1/Command/GetFeatureDefinition"]),
)


def text_ok(value: str) -> bool:
    """What the servers accept as a free-text parameter (sila_labware.device.validation.check_text)."""
    return len(value) <= MAX_TEXT_LENGTH and all(ord(character) >= 32 for character in value)


def handover_ok(position: str, sub_position: int, stations: dict[str, int] = STATIONS) -> bool:
    return position in stations and 1 <= sub_position <= stations[position]


# --- running one call ---------------------------------------------------------------------------

TALLY: Counter[str] = Counter()
OUTCOMES: Counter[str] = Counter()
_calls = concurrent.futures.ThreadPoolExecutor(max_workers=2, thread_name_prefix="bad-input-call")


def outcome_of(command: str, call: Callable[[], Any], *, may_succeed: bool = False) -> str:
    """Run one call with a deadline; return the SiLA error identifier (or "ok"), fail on anything else."""
    TALLY[command] += 1
    future = _calls.submit(call)
    try:
        future.result(timeout=CALL_DEADLINE_S)
        kind = "ok"
    except DefinedExecutionError as error:
        kind = f"defined:{error.identifier}"
    except ValidationError as error:
        # The server names the parameter; the sila2 client refuses a feature constraint itself.
        named = error.parameter_fully_qualified_identifier is not None
        assert named or "Constraint violated" in error.message, f"{command}: unnamed {error.message}"
        kind = "validation"
        OUTCOMES[f"{command} validation by {'server' if named else 'client'}"] += 1
        return kind
    except concurrent.futures.TimeoutError:
        pytest.fail(f"{command}: no answer within {CALL_DEADLINE_S:.0f} s")
    except Exception as error:  # noqa: BLE001 - the point: anything else is a finding
        pytest.fail(f"{command}: {type(error).__name__}: {error}")
    OUTCOMES[f"{command} {kind}"] += 1
    if kind == "ok" and not may_succeed:
        pytest.fail(f"{command} was accepted, but the input must be refused")
    return kind


def observable(start: Callable[[], Any]) -> Callable[[], Any]:
    """An observable command run to its end (its error is raised by get_responses)."""
    return lambda: finish(start(), timeout_s=CALL_DEADLINE_S)


# --- the stack and the state that must not change -------------------------------------------------


@pytest.fixture(scope="module")
def cell(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cell]:
    deployment: Deployment = start_stack(tmp_path_factory.mktemp("bad_input"), insecure=True)
    try:
        served = Cell(deployment)
        # The strategies below are written for the default world: check it is the one served.
        offered = served.manipulator.AvailableHandoverPositions.get()
        assert {item.Position: item.SubPosition for item in offered} == STATIONS
        assert set(served.robot.MobileRobotController.PointsOfInterest.get()) == set(POINTS_OF_INTEREST)
        yield served
    finally:
        deployment.stop()
        _report_tally(tmp_path_factory.getbasetemp() / "bad_input_counts.json")


def _report_tally(path: Path) -> None:
    report = {"inputs_tried": sum(TALLY.values()), "per_command": dict(TALLY), "outcomes": dict(OUTCOMES)}
    text = json.dumps(report, indent=1, sort_keys=True)
    path.write_text(text + "\n")
    if os.environ.get("BAD_INPUT_REPORT"):
        Path(os.environ["BAD_INPUT_REPORT"]).write_text(text + "\n")
    sys.stdout.write(f"\nbad inputs tried: {report['inputs_tried']} ({path})\n{text}\n")


def snapshot(cell: Cell) -> dict[str, Any]:
    """Everything a refused command must leave alone."""
    try:
        cell.robot.LabwareInventory.LocateLabware(LabwareUniqueID=PLATE)
        plate = "located"
    except DefinedExecutionError as error:
        plate = error.identifier
    motion = cell.robot.MobileRobotController
    return {
        "plate": plate,
        "locations": [
            (item.LabwareUniqueID, item.Aboard, item.Position, item.Index)
            for item in cell.robot.LabwareInventory.LabwareLocations.get()
        ],
        "nests": cell.nest_occupied(),
        "robot_state": motion.RobotState.get(),
        "onboard": list(motion.OnboardLabware.get()),
        "poi": motion.CurrentPointOfInterest.get(),
    }


@pytest.fixture()
def unchanged(cell: Cell) -> Iterator[Cell]:
    """The test's calls must leave the inventory, the nests and the robot as they were."""
    before = snapshot(cell)
    assert before["robot_state"] == "Docked" and before["nests"][("station_a", 1)]
    yield cell
    assert snapshot(cell) == before


def still_answering(cell: Cell) -> None:
    assert cell.manipulator.NumberOfInternalPositions.get() == HOTEL_SLOTS
    for station in STATIONS:
        assert cell.site(station).NumberOfInternalPositions.get() == 1


# --- the robot: LabwareTransferManipulatorController ----------------------------------------------


@EXAMPLES
@given(station_name, index, index, free_text, free_text)
def test_robot_prepare_for_input_refuses_bad_input(
    unchanged: Cell, position: str, sub_position: int, internal: int, labware_type: str, labware_id: str
) -> None:
    # All valid would start a drive; the hotel is empty, so nothing else refuses it.
    assume(
        not (
            handover_ok(position, sub_position)
            and 1 <= internal <= HOTEL_SLOTS
            and text_ok(labware_type)
            and text_ok(labware_id)
        )
    )
    kind = outcome_of(
        "Manipulator.PrepareForInput",
        observable(
            lambda: unchanged.manipulator.PrepareForInput(
                HandoverPosition=(position, sub_position),
                InternalPosition=internal,
                LabwareType=labware_type,
                LabwareUniqueID=labware_id,
            )
        ),
    )
    assert kind == "validation"  # parameters are checked before anything else
    still_answering(unchanged)


@EXAMPLES
@given(station_name, index, index)
@example("station_b", 2, 2)  # valid, but the hotel holds no plate
def test_robot_prepare_for_output_refuses_bad_input_and_an_empty_hotel(
    unchanged: Cell, position: str, sub_position: int, internal: int
) -> None:
    # Valid parameters are refused too: the hotel holds no plate (wrong order).
    kind = outcome_of(
        "Manipulator.PrepareForOutput",
        observable(
            lambda: unchanged.manipulator.PrepareForOutput(
                HandoverPosition=(position, sub_position), InternalPosition=internal
            )
        ),
    )
    valid = handover_ok(position, sub_position) and 1 <= internal <= HOTEL_SLOTS
    assert kind == ("defined:InvalidCommandSequence" if valid else "validation")
    still_answering(unchanged)


@pytest.mark.parametrize("command", ["GetLabware", "PutLabware"])
@EXAMPLES
@given(station_name, index, action_list)
@example("station_a", 1, [])  # valid, but not prepared
@example("station_b", 2, [])
def test_robot_get_and_put_refuse_bad_input_and_wrong_order(
    unchanged: Cell, command: str, position: str, sub_position: int, actions: list[str]
) -> None:
    # Nothing was prepared, so even valid parameters are the wrong order.
    start = getattr(unchanged.manipulator, command)
    kind = outcome_of(
        f"Manipulator.{command}",
        observable(lambda: start(HandoverPosition=(position, sub_position), IntermediateActions=actions)),
    )
    # No intermediate action is offered, so any listed one is a bad parameter.
    valid = handover_ok(position, sub_position) and not actions
    assert kind == ("defined:InvalidCommandSequence" if valid else "validation")
    still_answering(unchanged)


# --- the robot: MobileRobotController and LabwareInventory ---------------------------------------


@EXAMPLES
@given(st.one_of(st.sampled_from(POINTS_OF_INTEREST), any_text))
def test_drive_refuses_unknown_points_and_any_point_while_docked(unchanged: Cell, poi: str) -> None:
    kind = outcome_of(
        "MobileRobot.DriveToPointOfInterest",
        observable(lambda: unchanged.robot.MobileRobotController.DriveToPointOfInterest(PointOfInterest=poi)),
    )
    if not poi or not text_ok(poi) or poi not in POINTS_OF_INTEREST:
        assert kind == "validation"  # an unknown point of interest is refused at initiation
    else:
        assert kind == "defined:RobotDocked"
    still_answering(unchanged)


def test_parameterless_motion_commands_are_harmless_when_docked(unchanged: Cell) -> None:
    """Dock while docked and StopMotion at rest succeed at once and move nothing (Undock is a real
    motion, covered by the transfer tests)."""
    motion = unchanged.robot.MobileRobotController
    for _repeat in range(5):
        assert outcome_of("MobileRobot.Dock", observable(motion.Dock), may_succeed=True) == "ok"
        assert outcome_of("MobileRobot.StopMotion", motion.StopMotion, may_succeed=True) == "ok"
    still_answering(unchanged)


@EXAMPLES
@given(any_text)
def test_locate_unknown_labware_is_a_defined_error(unchanged: Cell, labware_id: str) -> None:
    known = {item.LabwareUniqueID for item in unchanged.robot.LabwareInventory.LabwareLocations.get()}
    kind = outcome_of(
        "Inventory.LocateLabware",
        lambda: unchanged.robot.LabwareInventory.LocateLabware(LabwareUniqueID=labware_id),
        may_succeed=labware_id in known,
    )
    # The inventory knows only the plates its sensors see (by their labels) until a scheduler names
    # one; an empty id or one over 255 characters breaks the feature's length constraints (the sila2
    # client refuses it itself).
    within_constraints = 1 <= len(labware_id) <= MAX_TEXT_LENGTH
    expected = (
        "ok" if labware_id in known else "defined:UnknownLabware" if within_constraints else "validation"
    )
    assert kind == expected


# --- the stations: LabwareTransferSiteController -------------------------------------------------


@EXAMPLES
@given(known_station, station_name, index, index, free_text, free_text)
@example("station_a", "station_a", 1, 1, "", "")  # valid, but the nest is occupied
def test_station_prepare_for_input_refuses_bad_input_and_occupied_nests(
    unchanged: Cell,
    station: str,
    position: str,
    sub_position: int,
    internal: int,
    labware_type: str,
    labware_id: str,
) -> None:
    valid = (
        handover_ok(position, sub_position, {station: STATIONS[station]})
        and internal == 1
        and text_ok(labware_type)
        and text_ok(labware_id)
    )
    # Valid parameters are refused only for the occupied nest; anything else would prepare a nest.
    assume(not valid or (position, sub_position) == ("station_a", 1))
    expected = "defined:InvalidCommandSequence" if valid else "validation"
    kind = outcome_of(
        "Site.PrepareForInput",
        observable(
            lambda: unchanged.site(station).PrepareForInput(
                HandoverPosition=(position, sub_position),
                InternalPosition=internal,
                LabwareType=labware_type,
                LabwareUniqueID=labware_id,
            )
        ),
    )
    assert kind == expected
    still_answering(unchanged)


@EXAMPLES
@given(known_station, station_name, index, index)
@example("station_b", "station_b", 2, 1)  # valid, but the nest is empty
@example("station_a", "station_a", 2, 1)
def test_station_prepare_for_output_refuses_bad_input_and_empty_nests(
    unchanged: Cell, station: str, position: str, sub_position: int, internal: int
) -> None:
    valid = handover_ok(position, sub_position, {station: STATIONS[station]}) and internal == 1
    # Valid parameters are refused only for an empty nest; the plate's nest would be prepared.
    assume(not valid or (position, sub_position) != ("station_a", 1))
    expected = "defined:InvalidCommandSequence" if valid else "validation"
    kind = outcome_of(
        "Site.PrepareForOutput",
        observable(
            lambda: unchanged.site(station).PrepareForOutput(
                HandoverPosition=(position, sub_position), InternalPosition=internal
            )
        ),
    )
    assert kind == expected
    still_answering(unchanged)


@pytest.mark.parametrize("command", ["LabwareDelivered", "LabwareRemoved"])
@EXAMPLES
@given(known_station, station_name, index)
@example("station_a", "station_a", 1)  # valid, but not prepared
@example("station_b", "station_b", 2)
def test_station_completions_refuse_bad_input_and_wrong_order(
    unchanged: Cell, command: str, station: str, position: str, sub_position: int
) -> None:
    # No nest was prepared, so even valid parameters are the wrong order (refused without waiting
    # for the nest sensor).
    start = getattr(unchanged.site(station), command)
    kind = outcome_of(f"Site.{command}", observable(lambda: start(HandoverPosition=(position, sub_position))))
    valid = handover_ok(position, sub_position, {station: STATIONS[station]})
    assert kind == ("defined:InvalidCommandSequence" if valid else "validation")
    still_answering(unchanged)
