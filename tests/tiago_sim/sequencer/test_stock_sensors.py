"""A lab with none of the lab-added plate sensors, as with a stock TIAGo++: real processes over DDS.

The world file says `sensors: {nests: false, hotel: false, label_readers: false}`. The robot then
checks a nest with its head camera's depth image and its hotel with the fingers' gap, and names
plates by the goals' words. Two plates: plate_001 in station_a:1, plate_002 in station_b:1, which
the robot's inventory does not know of (no sensor told it). Physics (/check_placement) judges;
the tests run in file order, the plates moving on from one to the next.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from action_msgs.msg import GoalStatus
from labware_interfaces.action import GetLabware, PutLabware
from labware_interfaces.msg import ErrorCodes, LabwareInventory, RobotState
from labware_interfaces.srv import CheckPlacement, DescribeWorkcell
from rcl_interfaces.srv import SetParameters

from tests.helpers.ros_processes import RosCaller, robot_side
from tests.helpers.sim_parameters import parameter_request
from tests.helpers.world_variants import default_world_with

TASK_TIMEOUT_S = 240.0


def stock_lab(folder: Path) -> Path:
    sensors = {"nests": False, "hotel": False, "label_readers": False}
    return default_world_with(folder / "stock_lab.yaml", {"plate_002": ("station_b", 1)}, sensors=sensors)


@pytest.fixture(scope="module")
def robot(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RosCaller]:
    logs = tmp_path_factory.mktemp("ros_logs")
    world = stock_lab(logs)
    with robot_side(logs, "test_stock_sensors", "--world", str(world), "--seed", "7") as caller:
        caller.subscribe(RobotState, "/robot_state")
        caller.subscribe(LabwareInventory, "/labware_inventory")
        caller.action_client(GetLabware, "/get_labware", timeout_s=60.0)
        caller.action_client(PutLabware, "/put_labware", timeout_s=60.0)
        caller.wait_for(lambda: len(caller.latest) == 2, 30.0, "the robot state and the inventory")
        yield caller


def transfer(robot: RosCaller, kind: type, station: str, sub_position: int, plate: str) -> object:
    goal = kind.Goal()
    goal.handover_position, goal.sub_position, goal.internal_position = station, sub_position, 1
    goal.labware_type, goal.labware_id = "sbs_microplate_96", plate
    name = "/get_labware" if kind is GetLabware else "/put_labware"
    return robot.call_action(kind, name, goal, timeout_s=TASK_TIMEOUT_S)


def where(robot: RosCaller, plate: str, station: str = "", sub_position: int = 0) -> CheckPlacement.Response:
    request = CheckPlacement.Request(labware_id=plate, station=station, sub_position=sub_position)
    return robot.call_service(CheckPlacement, "/check_placement", request)


def booked(robot: RosCaller) -> dict[str, str]:
    """The robot side's inventory: plate -> where it places it."""
    robot.spin_for(0.5)
    return {record.labware_id: record.location for record in robot.latest["/labware_inventory"].records}


def test_the_robot_reads_no_lab_added_sensor(robot: RosCaller) -> None:
    response = robot.call_service(DescribeWorkcell, "/describe_workcell", DescribeWorkcell.Request())
    assert (response.nest_sensors, response.hotel_sensors, response.label_readers) == (False, False, False)
    state = robot.latest["/robot_state"]
    assert list(state.hotel) == [] and state.held_labware_id == "" and not state.holding


def test_a_plate_goes_into_the_hotel_checked_by_the_fingers(robot: RosCaller) -> None:
    outcome = transfer(robot, GetLabware, "station_a", 1, "plate_001")
    assert outcome.result.success, f"{outcome.result.error_code} {outcome.result.message}"
    assert where(robot, "plate_001").location == "hotel:1"
    assert booked(robot)["plate_001"] == "hotel:1"


def test_a_nest_the_camera_sees_full_is_refused_and_nothing_moves(robot: RosCaller) -> None:
    """station_b:1 holds plate_002, which no sensor reported: the head camera sees it before the arm
    reaches into the hotel, and the plate stays aboard."""
    outcome = transfer(robot, PutLabware, "station_b", 1, "plate_001")
    assert outcome.status == GoalStatus.STATUS_ABORTED
    assert outcome.result.error_code == ErrorCodes.NEST_OCCUPIED, outcome.result.message
    assert "the head camera sees a plate in nest station_b/1" in outcome.result.message
    phases = [feedback.phase for feedback in outcome.feedback]
    assert not any(phase.startswith("to hotel") for phase in phases), phases
    assert where(robot, "plate_001").location == "hotel:1"
    assert where(robot, "plate_002", "station_b", 1).in_nest
    assert booked(robot)["plate_001"] == "hotel:1"


def test_a_free_nest_takes_the_plate_and_the_camera_confirms_it(robot: RosCaller) -> None:
    outcome = transfer(robot, PutLabware, "station_b", 2, "plate_001")
    assert outcome.result.success, f"{outcome.result.error_code} {outcome.result.message}"
    assert where(robot, "plate_001", "station_b", 2).in_nest
    assert booked(robot)["plate_001"] == "station:station_b:2"


def test_a_plate_knocked_out_after_the_release_is_seen_missing_by_the_camera(robot: RosCaller) -> None:
    outcome = transfer(robot, GetLabware, "station_b", 2, "plate_001")
    assert outcome.result.success, outcome.result.message
    request = parameter_request("fault.knock_plate", "plate_001")
    assert robot.call_service(SetParameters, "/tiago_sim/set_parameters", request).results[0].successful
    outcome = transfer(robot, PutLabware, "station_a", 1, "plate_001")
    assert outcome.status == GoalStatus.STATUS_ABORTED
    assert outcome.result.error_code == ErrorCodes.PLACE_FAILED, outcome.result.message
    assert "the head camera sees no plate in nest station_a/1" in outcome.result.message
    assert where(robot, "plate_001").location == "floor"
    assert booked(robot)["plate_001"] == "unknown"
