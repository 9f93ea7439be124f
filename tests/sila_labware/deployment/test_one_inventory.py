"""Two front doors, one truth: a plate moved through Bluesky shows over SiLA, and the reverse.

One `serve`-like deployment; the Bluesky device reaches its robot side as a separate ROS client
(its own runtime and RobotLink in the deployment's domain, as examples/bluesky_exchange.py does),
the SiLA side through its robot server. Both read the robot side's one inventory, so each door
must see the other's move within one state report (1 s here).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from bluesky import RunEngine
from bluesky import plan_stubs as bps

from labware_model.holders import Nest
from ros_bridge.bluesky import LabwareTransferRobot
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime
from tests.helpers.sila_stack import start_stack
from tests.helpers.transfer_steps import Cell

NAME = "bluesky-7"  # the plate's name for both doors; its label reads plate_001
A1, B1 = ("station_a", 1), ("station_b", 1)
CONSISTENT_WITHIN_S = 1.0


@pytest.fixture(scope="module")
def cell(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cell]:
    deployment = start_stack(tmp_path_factory.mktemp("one_inventory"), insecure=True)
    yield Cell(deployment)
    deployment.stop()


@pytest.fixture(scope="module")
def bluesky_robot(cell: Cell) -> Iterator[LabwareTransferRobot]:
    with RosRuntime("bluesky_door", domain_id=cell.deployment.domain_id) as runtime:
        link = RobotLink(runtime)
        link.wait_until_ready(60.0)
        yield LabwareTransferRobot(link, storage=Nest(*A1), beam=Nest(*B1), labware_id=NAME, name="robot")


def within(seconds: float, read: Callable[[], Any], wanted: Any) -> float:
    """How long until `read()` returns `wanted`; fails after `seconds`."""
    started = time.monotonic()
    while (seen := read()) != wanted:
        assert time.monotonic() - started < seconds, f"still {seen!r}, not {wanted!r}, after {seconds} s"
        time.sleep(0.02)
    return time.monotonic() - started


def test_a_plate_bluesky_moved_is_where_sila_says(cell: Cell, bluesky_robot: LabwareTransferRobot) -> None:
    engine = RunEngine({})
    engine(bps.mv(bluesky_robot, "pickup"))
    within(CONSISTENT_WITHIN_S, lambda: cell.location(NAME), (True, "", 1))
    engine(bps.mv(bluesky_robot, "place"))
    within(CONSISTENT_WITHIN_S, lambda: cell.location(NAME), (False, *B1))
    assert cell.deployment.link is not None
    assert cell.deployment.link.check_placement("plate_001", Nest(*B1)).in_nest  # the physics agrees


def test_a_plate_sila_moved_is_where_bluesky_says(cell: Cell, bluesky_robot: LabwareTransferRobot) -> None:
    cell.transfer(B1, A1, NAME)
    within(
        CONSISTENT_WITHIN_S,
        lambda: bluesky_robot.labware_locations.get(),
        f"{NAME}=station:station_a:1",
    )
    assert bluesky_robot.carried_labware.get() == ""
