"""`sila-labware bluesky-demo`: the beamline sample exchange on a RunEngine against the running robot.

The robot side (simulation and sequencer, or a real robot serving the same ROS names) must
already be running in this ROS domain. The demo asks the robot which stations it serves and
where the plate is: the plate's nest becomes the storage site and the first free nest of another
station the beam site. It then runs `sample_exchange_plan` with a simulated stage and detector
(ophyd.sim) and finally asks the simulation's ground truth (/check_placement) whether the plate
rests in its starting nest again: only then does it return 0.

Threads: the RunEngine runs on the caller's thread (its event loop on its own thread); the ROS
bridge adds one ROS thread, stopped before returning.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bluesky import RunEngine
from bluesky.utils import ProgressBarManager, RunEngineInterrupted
from ophyd.sim import SynAxis, SynGauss

from labware_model.holders import Nest, location_text
from ros_bridge.bluesky.device import LabwareTransferRobot
from ros_bridge.bluesky.plan import sample_exchange_plan
from ros_bridge.errors import BridgeError
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime

logger = logging.getLogger(__name__)

LOAD_POSITION_M = 0.0
MEASURE_POSITION_M = 0.26  # the beamline paper moved its stage by 26 cm


@dataclass(frozen=True)
class ExchangeSetup:
    """What the robot side reported: the plate, where it is stored, where it is measured."""

    labware_id: str
    storage: Nest
    beam: Nest
    hotel_slot: int


def find_exchange_setup(link: RobotLink) -> ExchangeSetup:
    """The first plate the station sensors report, a free nest on another station, a free hotel slot."""
    workcell = link.describe_workcell()
    readings = link.nest_readings()
    plate_reading = next((reading for reading in readings if reading.occupied and reading.labware_id), None)
    if plate_reading is None:
        raise BridgeError("no station reports a plate with a known id")
    plate_nest = plate_reading.nest
    free_nest = next(
        (
            reading.nest
            for reading in readings
            if not reading.occupied and reading.nest.station != plate_nest.station
        ),
        None,
    )
    if free_nest is None:
        stations = ", ".join(station.name for station in workcell.stations)
        raise BridgeError(f"no free nest on a station other than {plate_nest.station} (stations: {stations})")
    robot = link.robot_status()
    used_slots = {reading.slot.index for reading in robot.hotel if reading.labware_id}
    free_slots = [index for index in range(1, workcell.hotel_slots + 1) if index not in used_slots]
    if not free_slots:
        raise BridgeError("every hotel slot on the robot is occupied")
    return ExchangeSetup(
        labware_id=plate_reading.labware_id,
        storage=plate_nest,
        beam=free_nest,
        hotel_slot=free_slots[0],
    )


class DocumentLog:
    """A RunEngine subscriber that logs what the run records, one line per document of interest."""

    def __init__(self) -> None:
        self._stream_of_descriptor: dict[str, str] = {}
        self.event_count = 0

    def __call__(self, name: str, document: dict[str, Any]) -> None:
        if name == "start":
            logger.info("run %s started (plan %s)", document["uid"][:8], document.get("plan_name"))
        elif name == "descriptor":
            self._stream_of_descriptor[document["uid"]] = document.get("name", "")
        elif name == "event":
            self.event_count += 1
            stream = self._stream_of_descriptor.get(document["descriptor"], "?")
            shown = ", ".join(f"{key}={_short(value)}" for key, value in sorted(document["data"].items()))
            logger.info("event %d [%s]: %s", document["seq_num"], stream, shown)
        elif name == "stop":
            logger.info("run ended: %s %s", document.get("exit_status"), document.get("reason", ""))


def _short(value: Any) -> str:
    return f"{value:.4g}" if isinstance(value, float) else repr(value)


def build_devices(
    link: RobotLink, setup: ExchangeSetup, task_timeout_s: float = 600.0
) -> tuple[LabwareTransferRobot, SynAxis, SynGauss]:
    """The robot, a simulated stage (m) and a detector whose signal peaks at the measure position."""
    robot = LabwareTransferRobot(
        link,
        storage=setup.storage,
        beam=setup.beam,
        labware_id=setup.labware_id,
        hotel_slot=setup.hotel_slot,
        task_timeout_s=task_timeout_s,
        name="robot",
    )
    stage = SynAxis(name="stage", value=LOAD_POSITION_M)
    detector = SynGauss(
        "detector", stage, "stage", center=MEASURE_POSITION_M, Imax=1.0e5, sigma=0.05, noise="none"
    )
    return robot, stage, detector


def run_bluesky_demo(
    world_path: Path,
    *,
    domain_id: int | None = None,
    ready_timeout_s: float = 180.0,
    task_timeout_s: float = 600.0,
    progress_bar: bool = False,
    waiting_hook: Callable[[Any], None] | None = None,
    document_callbacks: Sequence[Callable[[str, dict[str, Any]], None]] = (),
) -> int:
    """Run the sample exchange plan on a RunEngine; 0 only if the plate ends in its starting nest.

    `progress_bar` draws bluesky's terminal progress bars (stdout); `waiting_hook` replaces them
    with your own (called with the status objects being waited on). `document_callbacks` get
    every document of the run, after the demo's own log lines.
    """
    started = time.monotonic()
    runtime = RosRuntime(node_name="bluesky_bridge", domain_id=domain_id).start()
    try:
        link = RobotLink(runtime)
        link.wait_until_ready(ready_timeout_s)
        setup = find_exchange_setup(link)
        logger.info(
            "plate %s: storage %s, beam %s, hotel slot %d",
            setup.labware_id,
            setup.storage,
            setup.beam,
            setup.hotel_slot,
        )
        robot, stage, detector = build_devices(link, setup, task_timeout_s)
        # Ctrl-C pauses the RunEngine (its SIGINT handler, main thread only); we then abort.
        on_main_thread = threading.current_thread() is threading.main_thread()
        engine = RunEngine({}) if on_main_thread else RunEngine({}, context_managers=[])
        if waiting_hook is not None:
            engine.waiting_hook = waiting_hook
        elif progress_bar:
            engine.waiting_hook = ProgressBarManager()
        engine.subscribe(DocumentLog())
        for callback in document_callbacks:
            engine.subscribe(callback)
        plan = sample_exchange_plan(
            robot,
            stage,
            detector,
            measure_position=MEASURE_POSITION_M,
            load_position=LOAD_POSITION_M,
            md={"world": str(world_path)},
        )
        try:
            engine(plan)
        except RunEngineInterrupted:
            engine.abort("interrupted")
            raise
        check = link.check_placement(setup.labware_id, setup.storage)
    except Exception as error:  # noqa: BLE001 - the demo reports every failure as exit code 1
        logger.error("bluesky demo failed: %s", _reason(error))
        return 1
    finally:
        runtime.stop()
    if not check.in_nest:
        logger.error("the plate is not back in %s; it is at %s", setup.storage, location_text(check.location))
        return 1
    logger.info(
        "plate %s back in %s (%.1f mm off centre) after %.0f s",
        setup.labware_id,
        setup.storage,
        1000.0 * check.position_error_m,
        time.monotonic() - started,
    )
    return 0


def _reason(error: BaseException) -> str:
    """The innermost cause: bluesky wraps a failed status as FailedStatus(status) from the action error."""
    while error.__cause__ is not None:
        error = error.__cause__
    return str(error)
