"""The beamline sample exchange on a real RunEngine against the simulated robot over DDS.

sim_node and sequencer run as real processes; the robot device talks to them only through the
ROS bridge. Ground truth (/check_placement) judges where the plate ends up. The tests share
the processes and run in file order: refusal (robot still docked), stop during the drive,
the demo's full plan, and last an occluded marker at station A (where the full plan leaves the robot).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from bluesky import RunEngine
from bluesky.utils import FailedStatus, RunEngineInterrupted
from ophyd.sim import SynAxis, SynGauss

from labware_model.holders import Nest
from ros_bridge.bluesky import ActionFailed, LabwareTransferRobot, sample_exchange_plan
from ros_bridge.bluesky.demo import MEASURE_POSITION_M, find_exchange_setup, run_bluesky_demo
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime
from tests.helpers.ros_processes import running
from tests.helpers.sim_parameters import set_node_parameter

DEFAULT_WORLD = Path(__file__).resolve().parents[2] / "lab_description" / "worlds" / "default.yaml"
PLATE = "plate_001"
STORAGE = Nest("station_a", 1)
BEAM = Nest("station_b", 1)
MEASURE_M, LOAD_M = 0.26, 0.0
MOVING_STATES = ("navigating", "manipulating")


@pytest.fixture(scope="module")
def link(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RobotLink]:
    logs = tmp_path_factory.mktemp("bluesky_logs")
    with (
        running("tiago_twin", "--seed", "7", log_path=logs / "sim_node.log") as sim,
        running("tiago_sim.sequencer", log_path=logs / "sequencer.log") as sequencer,
        RosRuntime("bluesky_plan_test") as runtime,
    ):
        robot_link = RobotLink(runtime)
        robot_link.wait_until_ready(timeout_s=120.0)
        yield robot_link
        for process, name in ((sim, "sim_node"), (sequencer, "sequencer")):
            assert process.poll() is None, f"{name} died early; see {logs / (name + '.log')}"
    for name in ("sim_node", "sequencer"):
        assert "Traceback" not in (logs / f"{name}.log").read_text(), f"{name} logged a traceback"


class Documents:
    """Every document the RunEngine emits, with events sorted by stream."""

    def __init__(self) -> None:
        self.all: list[tuple[str, dict[str, Any]]] = []

    def __call__(self, name: str, document: dict[str, Any]) -> None:
        self.all.append((name, document))

    def of(self, kind: str) -> list[dict[str, Any]]:
        return [document for name, document in self.all if name == kind]

    def events(self, stream: str) -> list[dict[str, Any]]:
        descriptors = {d["uid"] for d in self.of("descriptor") if d["name"] == stream}
        return [event for event in self.of("event") if event["descriptor"] in descriptors]


def make_robot(link: RobotLink, storage: Nest = STORAGE, beam: Nest = BEAM) -> LabwareTransferRobot:
    return LabwareTransferRobot(
        link, storage=storage, beam=beam, labware_id=PLATE, hotel_slot=1, task_timeout_s=300.0
    )


def make_engine() -> tuple[RunEngine, Documents]:
    engine = RunEngine({}, context_managers=[])
    documents = Documents()
    engine.subscribe(documents)
    return engine, documents


def exchange(robot: LabwareTransferRobot) -> Any:
    stage = SynAxis(name="stage", value=LOAD_M)
    detector = SynGauss("detector", stage, "stage", center=MEASURE_M, Imax=1000.0, sigma=0.05, noise="none")
    return sample_exchange_plan(robot, stage, detector, measure_position=MEASURE_M, load_position=LOAD_M)


def assert_plate_in(link: RobotLink, site: Nest) -> None:
    check = link.check_placement(PLATE, site)
    assert check.in_nest, f"plate not in {site}: {check}"


def set_sim_parameter(link: RobotLink, name: str, value: str | float) -> None:
    set_node_parameter(link.runtime, name, value)


def test_the_workcell_offers_the_exchange_the_tests_assume(link: RobotLink) -> None:
    setup = find_exchange_setup(link)
    assert (setup.labware_id, setup.storage, setup.beam, setup.hotel_slot) == (PLATE, STORAGE, BEAM, 1)


def test_unknown_station_fails_the_plan_with_the_robots_reason(link: RobotLink) -> None:
    engine, documents = make_engine()
    with pytest.raises(FailedStatus) as failure:
        engine(exchange(make_robot(link, storage=Nest("mars", 1))))
    cause = failure.value.__cause__
    assert isinstance(cause, ActionFailed) and cause.error_code == "UNKNOWN_STATION", cause
    assert "mars" in cause.message
    (stop,) = documents.of("stop")
    assert stop["exit_status"] == "fail" and "UNKNOWN_STATION" in stop["reason"] and "mars" in stop["reason"]
    assert documents.events("primary") == []
    assert_plate_in(link, STORAGE)


def test_pause_and_abort_while_driving_cancels_the_goal_and_the_robot_stops(link: RobotLink) -> None:
    engine, documents = make_engine()
    robot = make_robot(link)

    def pause_once_driving() -> None:
        deadline = time.monotonic() + 120.0
        while time.monotonic() < deadline:
            status = robot.current_status
            if status is not None and status.progress.phase.startswith("driving"):
                time.sleep(0.5)  # well into the drive
                engine.request_pause(defer=False)
                return
            time.sleep(0.05)

    pauser = threading.Thread(target=pause_once_driving, daemon=True)
    pauser.start()
    # The simulation runs faster than real time when it can: hold it to real time so the
    # drive (several metres) is surely still under way when the pause comes.
    set_sim_parameter(link, "realtime_factor_cap", 1.0)
    try:
        with pytest.raises(RunEngineInterrupted):
            engine(exchange(robot))
        pauser.join(timeout=5.0)
        engine.abort("test: operator abort while driving")
    finally:
        set_sim_parameter(link, "realtime_factor_cap", 0.0)

    status = robot.current_status
    assert status is not None and status.label.startswith("pickup")
    with pytest.raises(ActionFailed) as cancelled:
        status.wait(timeout=20.0)
    assert cancelled.value.error_code == "CANCELED", cancelled.value
    stopped = link.wait_for_robot_status(lambda robot: robot.state not in MOVING_STATES, timeout_s=10.0)
    time.sleep(1.0)
    later = link.robot_status()
    assert later.state not in MOVING_STATES, later
    assert abs(later.x_m - stopped.x_m) < 0.01 and abs(later.y_m - stopped.y_m) < 0.01, "the base kept moving"
    assert later.current_poi != "station_a_work", "the drive should have been cut short"
    (stop,) = documents.of("stop")
    assert stop["exit_status"] == "abort"
    assert_plate_in(link, STORAGE)


def test_bluesky_demo_measures_and_returns_the_plate(link: RobotLink) -> None:
    documents = Documents()
    progress_reports: list[dict[str, Any]] = []

    def watch_statuses(statuses: Any) -> None:
        for status in statuses or ():
            if hasattr(status, "watch"):
                status.watch(lambda **report: progress_reports.append(report))

    exit_code = run_bluesky_demo(
        DEFAULT_WORLD, ready_timeout_s=30.0, waiting_hook=watch_statuses, document_callbacks=[documents]
    )
    assert exit_code == 0

    (stop,) = documents.of("stop")
    assert stop["exit_status"] == "success", stop
    (start,) = documents.of("start")
    assert start["labware_id"] == PLATE and start["storage_site"] == "station_a/1"
    assert start["beam_site"] == "station_b/1" and start["world"] == str(DEFAULT_WORLD)
    (measurement,) = documents.events("primary")
    assert measurement["data"]["detector"] == pytest.approx(1.0e5)
    assert measurement["data"]["stage"] == pytest.approx(MEASURE_POSITION_M)
    assert measurement["data"]["robot_state"] == "idle"
    assert measurement["data"]["robot_carried_labware"] == ""
    assert measurement["data"]["robot_current_poi"] == "station_b_work"
    robot_events = documents.events("robot")
    assert [(e["data"]["robot_last_task"], e["data"]["robot_carried_labware"]) for e in robot_events] == [
        ("pickup", PLATE),
        ("place", ""),
        ("return_pickup", PLATE),
        ("return_place", ""),
    ]
    assert robot_events[-1]["data"]["robot_current_poi"] == "station_a_work"
    robot_progress = [r for r in progress_reports if "current" in r and r["name"].startswith("robot ")]
    for task in ("pickup", "place", "return_pickup", "return_place"):
        currents = [r["current"] for r in robot_progress if r["name"].startswith(f"robot {task} ")]
        assert currents and currents[-1] == 100.0 and min(currents) < 50.0, (task, currents[:5])
    assert_plate_in(link, STORAGE)
    assert PLATE not in link.robot_status().onboard_labware_ids


def test_occluded_marker_fails_the_plan_and_leaves_the_plate(link: RobotLink) -> None:
    engine, documents = make_engine()
    set_sim_parameter(link, "fault.occlude_marker", STORAGE.station)
    try:
        with pytest.raises(FailedStatus) as failure:
            engine(exchange(make_robot(link)))
    finally:
        set_sim_parameter(link, "fault.occlude_marker", "")
    cause = failure.value.__cause__
    assert isinstance(cause, ActionFailed) and cause.error_code == "MARKER_NOT_FOUND", cause
    assert "marker not found" in cause.message
    (stop,) = documents.of("stop")
    assert stop["exit_status"] == "fail" and "MARKER_NOT_FOUND" in stop["reason"]
    assert_plate_in(link, STORAGE)
