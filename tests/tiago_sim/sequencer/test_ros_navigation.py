"""Navigation through ROS only, in a lab with a third bench across the straight line from A to B.

sim_node + sequencer run as real processes over DDS on lab_description/worlds/bench_in_the_way.yaml.
/map and /plan are read by plain rclpy subscribers with the QoS RViz's Map and Path displays use
(the map latched: transient local). The transfer A -> B must go around bench_c with no contact
(a contact fails the running goal with COLLISION); a POI moved into the bench is refused with
NAVIGATION_FAILED naming why, before anything moves.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import pytest
from labware_interfaces.action import GetLabware, NavigateToPoi, PutLabware
from labware_interfaces.msg import ErrorCodes, RobotState
from labware_interfaces.srv import CheckPlacement
from nav_msgs.msg import OccupancyGrid, Path
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from lab_description.world import DEFAULT_WORLD, load_world
from tests.helpers.ros_processes import RosCaller, running
from tiago_sim.navigation.planner import INFLATION_RADIUS_M

WORLD = DEFAULT_WORLD.parent / "bench_in_the_way.yaml"
PLATE = "plate_001"
TASK_TIMEOUT_S = 240.0


@pytest.fixture(scope="module")
def robot(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[RosCaller, list[Any]]]:
    logs = tmp_path_factory.mktemp("ros_logs")
    with (
        running("tiago_twin", "--world", str(WORLD), "--seed", "3", log_path=logs / "sim_node.log"),
        running("tiago_sim.sequencer", "--world", str(WORLD), log_path=logs / "sequencer.log"),
    ):
        caller = RosCaller("test_ros_navigation")
        plans: list[Any] = []
        try:
            latched = QoSProfile(
                depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
            )
            node = caller.node
            node.create_subscription(
                OccupancyGrid, "/map", lambda m: caller.latest.__setitem__("/map", m), latched
            )
            node.create_subscription(Path, "/plan", plans.append, QoSProfile(depth=10))
            caller.subscribe(RobotState, "/robot_state")
            caller.action_client(GetLabware, "/get_labware", timeout_s=60.0)
            caller.wait_for(lambda: "/map" in caller.latest and "/robot_state" in caller.latest, 30.0, "/map")
            yield caller, plans
        finally:
            caller.close()
    assert "collision:" not in (logs / "sim_node.log").read_text(), "the sim node logged a collision"


def task_goal(kind: type, station: str) -> Any:
    goal = kind.Goal()
    goal.handover_position, goal.sub_position, goal.internal_position = station, 1, 1
    goal.labware_type, goal.labware_id = "sbs_microplate_96", PLATE
    return goal


def test_the_map_is_latched_in_the_map_frame_at_5_cm_with_the_bench_on_it(robot: Any) -> None:
    caller, _ = robot
    grid = caller.latest["/map"]
    assert grid.header.frame_id == "map"
    assert grid.info.resolution == pytest.approx(0.05)
    assert (grid.info.width, grid.info.height) == (240, 240)
    assert (grid.info.origin.position.x, grid.info.origin.position.y) == (-6.0, -6.0)
    assert set(grid.data) == {0, 100}

    def value_at(x: float, y: float) -> int:
        col = math.floor((x - grid.info.origin.position.x) / grid.info.resolution)
        row = math.floor((y - grid.info.origin.position.y) / grid.info.resolution)
        return grid.data[row * grid.info.width + col]

    bench = load_world(WORLD).obstacles[0]
    assert value_at(bench.x, bench.y) == 100
    assert value_at(2.0, 0.0) == 100  # station_a's table
    assert value_at(-5.98, 0.0) == 100  # the west wall
    assert value_at(0.5, 1.0) == 0  # lab_centre


def test_the_plate_goes_from_a_to_b_around_the_bench_without_contact(robot: Any) -> None:
    caller, plans = robot
    world = load_world(WORLD)
    bench = world.obstacles[0]
    for kind, name, station in (
        (GetLabware, "/get_labware", "station_a"),
        (PutLabware, "/put_labware", "station_b"),
    ):
        outcome = caller.call_action(kind, name, task_goal(kind, station), timeout_s=TASK_TIMEOUT_S)
        assert outcome.result.success, (
            f"{name} {station}: {outcome.result.error_code} {outcome.result.message}"
        )
    check = caller.call_service(
        CheckPlacement,
        "/check_placement",
        CheckPlacement.Request(labware_id=PLATE, station="station_b", sub_position=1),
    )
    assert check.in_nest, check
    caller.spin_for(0.5)
    assert plans, "no /plan published"
    to_b = plans[-1]
    assert to_b.header.frame_id == "map"
    goal = world.pois["station_b_work"]
    last = to_b.poses[-1].pose
    assert (last.position.x, last.position.y) == pytest.approx((goal.x, goal.y), abs=1e-6)
    assert 2.0 * math.atan2(last.orientation.z, last.orientation.w) == pytest.approx(goal.yaw, abs=1e-6)
    points = [(pose.pose.position.x, pose.pose.position.y) for pose in to_b.poses]
    assert len(points) >= 3, "the straight line from A to B crosses bench_c: the path must bend"
    for (ax, ay), (bx, by) in zip(points, points[1:], strict=False):
        for k in range(51):
            t = k / 50
            assert bench.distance_to(ax + (bx - ax) * t, ay + (by - ay) * t) >= INFLATION_RADIUS_M - 0.05


def test_a_poi_inside_the_bench_is_navigation_failed_naming_why(robot: Any) -> None:
    caller, _ = robot
    bench = load_world(WORLD).obstacles[0]
    value = ParameterValue(
        type=ParameterType.PARAMETER_DOUBLE_ARRAY, double_array_value=[bench.x, bench.y, 0.0]
    )
    request = SetParameters.Request(parameters=[Parameter(name="pois.lab_centre", value=value)])
    response = caller.call_service(SetParameters, "/tiago_sim/set_parameters", request)
    assert response.results[0].successful, response.results[0].reason
    before = caller.latest["/robot_state"].base_pose
    outcome = caller.call_action(
        NavigateToPoi, "/navigate_to_poi", NavigateToPoi.Goal(poi="lab_centre"), 60.0
    )
    assert not outcome.result.success
    assert outcome.result.error_code == ErrorCodes.NAVIGATION_FAILED
    assert "no path to POI 'lab_centre'" in outcome.result.message
    assert f"the goal ({bench.x:.2f}, {bench.y:.2f}) is inside an obstacle" in outcome.result.message
    caller.spin_for(0.5)
    after = caller.latest["/robot_state"].base_pose
    assert math.hypot(after.x - before.x, after.y - before.y) < 0.005, "the base moved"
