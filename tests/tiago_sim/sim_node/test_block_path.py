"""Things not on the map: a box appears on the robot's path mid-drive (fault.block_path).

The sim node runs as a real process over DDS on the default world; the box is a real PyBullet
collision body the robot only learns of from its base laser. Distances are ground truth: the
/ground_truth/base_pose samples against the box pose the sim node logs when it places it, and the
sim thread's own closest approach (every batch of steps) logged when the box is removed. The
collision watch must stay silent throughout (checked in the sim node's log at the end).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from geometry_msgs.msg import Pose2D
from labware_interfaces.action import NavigateToPoi, Undock
from labware_interfaces.msg import ErrorCodes
from rcl_interfaces.srv import SetParameters
from rclpy.qos import QoSProfile, ReliabilityPolicy

from lab_description.world import DEFAULT_WORLD, load_world
from tests.helpers.ros_processes import RosCaller, running
from tests.helpers.sim_parameters import parameter_request
from tiago_description.robot_model import BASE_RADIUS
from tiago_sim.navigation.blockage import STOP_SHORT_M
from tiago_sim.sim_node.navigation import BLOCKED_TIMEOUT_S

BOX_LINE = re.compile(r"path-blocking box at x=(\S+) y=(\S+) yaw=(\S+) size (\S+) x (\S+) x")
CLOSEST_LINE = re.compile(r"the base came within (\S+) m of it")


@pytest.fixture(scope="module")
def robot(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[RosCaller, list[Pose2D], Path]]:
    log_path = tmp_path_factory.mktemp("ros_logs") / "sim_node.log"
    with running("tiago_twin", "--world", str(DEFAULT_WORLD), "--seed", "3", log_path=log_path):
        caller = RosCaller("test_block_path")
        truth: list[Pose2D] = []
        try:
            qos = QoSProfile(depth=50, reliability=ReliabilityPolicy.RELIABLE)
            caller.node.create_subscription(Pose2D, "/ground_truth/base_pose", truth.append, qos)
            outcome = caller.call_action(Undock, "/undock", Undock.Goal(), 60.0)
            assert outcome.result.success, outcome.result.message
            yield caller, truth, log_path
        finally:
            caller.close()
    assert "collision:" not in log_path.read_text(), "the sim node logged a collision"


def set_parameter(caller: RosCaller, name: str, value: str | float) -> None:
    response = caller.call_service(SetParameters, "/tiago_sim/set_parameters", parameter_request(name, value))
    assert response.results[0].successful, response.results[0].reason


def box_to_base_m(box: tuple[float, ...], x: float, y: float) -> float:
    """Ground-truth gap between the base (its BASE_RADIUS circle) and the box (x, y, yaw, l, w)."""
    bx, by, yaw, length, width = box
    along = (x - bx) * math.cos(yaw) + (y - by) * math.sin(yaw)
    across = -(x - bx) * math.sin(yaw) + (y - by) * math.cos(yaw)
    return math.hypot(max(abs(along) - length / 2, 0), max(abs(across) - width / 2, 0)) - BASE_RADIUS


def test_a_box_dropped_on_the_path_is_seen_stopped_short_of_and_driven_around(robot: Any) -> None:
    caller, truth, log_path = robot
    set_parameter(caller, "fault.block_path", "1.0")
    goal = load_world(DEFAULT_WORLD).pois["lab_centre"]
    goal_message = NavigateToPoi.Goal(poi="lab_centre")
    outcome = caller.call_action(NavigateToPoi, "/navigate_to_poi", goal_message, 120.0)
    caller.spin_for(1.0)  # the last ground-truth samples
    set_parameter(caller, "fault.block_path", "")
    caller.spin_for(0.5)
    text = log_path.read_text()
    assert outcome.result.success, f"{outcome.result.error_code}: {outcome.result.message}"
    placed = BOX_LINE.search(text)
    assert placed, "no box was placed during the drive"
    box = tuple(float(value) for value in placed.groups())
    assert "path blocked at sim" in text, "the robot never saw the box"
    assert "points not on the map marked" in text, "the robot did not plan around the box"
    samples = [box_to_base_m(box, pose.x, pose.y) for pose in truth]
    closest = CLOSEST_LINE.findall(text)
    assert closest, "the box was not removed"
    assert min(samples) >= STOP_SHORT_M, f"ground truth: the base came within {min(samples):.3f} m"
    assert float(closest[-1]) >= STOP_SHORT_M, f"the base came within {closest[-1]} m of the box"
    end = truth[-1]
    assert math.hypot(end.x - goal.x, end.y - goal.y) < 0.05, f"ended at ({end.x:.3f}, {end.y:.3f})"


def test_a_corridor_closed_completely_fails_navigation_naming_the_blockage(robot: Any) -> None:
    caller, _, log_path = robot
    set_parameter(caller, "idle_realtime_factor", 10.0)  # the wait is simulated time
    set_parameter(caller, "fault.block_path", "closed")
    outcome = caller.call_action(
        NavigateToPoi, "/navigate_to_poi", NavigateToPoi.Goal(poi="dock_approach"), 240.0
    )
    set_parameter(caller, "fault.block_path", "")
    set_parameter(caller, "idle_realtime_factor", 1.0)
    caller.spin_for(0.5)
    assert not outcome.result.success
    assert outcome.result.error_code == ErrorCodes.NAVIGATION_FAILED
    message = outcome.result.message
    assert "no path to POI 'dock_approach': blocked by an obstacle not on the map" in message, message
    assert f"for {BLOCKED_TIMEOUT_S:.0f} s" in message, message
    waiting = [feedback.phase for feedback in outcome.feedback if feedback.phase.startswith("waiting")]
    assert waiting, "progress never showed the robot waiting"
    assert "blocked by an obstacle not on the map" in waiting[0]
    closest = CLOSEST_LINE.findall(log_path.read_text())
    assert float(closest[-1]) >= STOP_SHORT_M, f"the base came within {closest[-1]} m of the wall"
