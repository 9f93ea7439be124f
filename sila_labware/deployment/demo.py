"""The demo transfer, done the way a lab scheduler would: as a plain SiLA client of our servers.

Moves the plate found on the first station to a free nest of the second, in the standard's order:
A.PrepareForOutput + Robot.PrepareForInput, Robot.GetLabware, A.LabwareRemoved,
B.PrepareForInput + Robot.PrepareForOutput, Robot.PutLabware, B.LabwareDelivered.
Success is judged from physics ground truth (/check_placement through the bridge), never from
what the commands reported.

Threads: runs on the caller's thread; sila2's client threads deliver execution infos.
"""

from __future__ import annotations

import logging
import math
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any, TextIO

from sila2.client import SilaClient

from labware_model.holders import Nest, location_text
from labware_model.readings import PlacementCheck
from sila_labware.deployment.stack import Deployment, ServedServer

logger = logging.getLogger(__name__)

COMMAND_TIMEOUT_S = 900.0
# The client notices a finished command within DONE_CHECK_S: every step waits for the previous one,
# and the idle robot's clock runs at 1x meanwhile (checked every 0.2 s, the six steps of a transfer
# lost about 0.6 s of wall and simulated time). The progress line is redrawn less often.
DONE_CHECK_S = 0.02
PROGRESS_REDRAW_S = 0.2


@dataclass
class StepTiming:
    name: str
    sim_seconds: float
    wall_seconds: float


@dataclass
class DemoReport:
    success: bool = False
    plate_position_error_mm: float | None = None
    plate_yaw_error_deg: float | None = None
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0
    steps: list[StepTiming] = field(default_factory=list)
    labware_id: str = ""
    source: str = ""
    destination: str = ""
    error: str = ""

    def as_json_object(self) -> dict[str, Any]:
        return asdict(self)


def connect(deployment: Deployment, served: ServedServer) -> SilaClient:
    if deployment.ca_file is None:
        return SilaClient(served.host, served.port, insecure=True)
    return SilaClient(served.host, served.port, root_certs=deployment.ca_file.read_bytes())


class ProgressLine:
    """One live line on a terminal stream: step name, progress bar, remaining time."""

    def __init__(self, stream: TextIO | None) -> None:
        self._stream = stream
        self._interactive = bool(stream is not None and stream.isatty())

    def show(self, step: str, progress: float, remaining_s: float | None) -> None:
        if self._stream is None or not self._interactive:
            return
        filled = int(round(20 * progress))
        remaining = f"{remaining_s:5.1f} s left" if remaining_s is not None else ""
        self._stream.write(
            f"\r{step:<48} [{'#' * filled}{'.' * (20 - filled)}] {100 * progress:5.1f} % {remaining}"
        )
        self._stream.flush()

    def done(self, step: str, wall_s: float, sim_s: float) -> None:
        if self._stream is None:
            return
        prefix = "\r" if self._interactive else ""
        self._stream.write(
            f"{prefix}{step:<48} done in {wall_s:6.1f} s wall, {sim_s:6.1f} s simulated{' ' * 12}\n"
        )
        self._stream.flush()


def run_commands(commands: list[Callable[[], Any]], step: str, progress_line: ProgressLine) -> None:
    """Start observable commands together and wait for all; their errors propagate."""
    instances = [command() for command in commands]
    deadline = time.monotonic() + COMMAND_TIMEOUT_S
    redraw_at = 0.0
    while not all(instance.done for instance in instances):
        now = time.monotonic()
        if now > deadline:
            raise TimeoutError(f"{step}: not finished after {COMMAND_TIMEOUT_S:.0f} s")
        if now >= redraw_at:
            redraw_at = now + PROGRESS_REDRAW_S
            progresses = [instance.progress or 0.0 for instance in instances]
            remaining = [instance.estimated_remaining_time for instance in instances]
            remaining_s = max(
                (value.total_seconds() for value in remaining if value is not None), default=None
            )
            progress_line.show(step, min(progresses), remaining_s)
        time.sleep(DONE_CHECK_S)
    for instance in instances:
        instance.get_responses()  # raises the command's SiLA error, if any


def run_demo(deployment: Deployment, progress_stream: TextIO | None = sys.stderr) -> DemoReport:
    """The standard transfer from the first station's plate to the second station."""
    assert deployment.link is not None and deployment.workcell is not None
    link = deployment.link
    report = DemoReport()
    stations = deployment.workcell.stations
    if len(stations) < 2:
        report.error = "the world needs at least two stations"
        return report
    source, destination = stations[0], stations[1]
    nests = link.nest_readings()
    plate_reading = next((n for n in nests if n.nest.station == source.name and n.occupied), None)
    free_reading = next((n for n in nests if n.nest.station == destination.name and not n.occupied), None)
    if plate_reading is None or free_reading is None:
        report.error = f"need a plate on {source.name} and a free nest on {destination.name}"
        return report
    plate_nest, free_nest = plate_reading.nest, free_reading.nest
    report.labware_id = plate_reading.labware_id
    report.source = str(plate_nest)
    report.destination = str(free_nest)
    pick = (plate_nest.station, plate_nest.sub_position)  # the SiLA HandoverPosition structure
    place = (free_nest.station, free_nest.sub_position)

    robot = connect(deployment, deployment.robot_server()).LabwareTransferManipulatorController
    site_a = connect(deployment, deployment.station_server(source.name)).LabwareTransferSiteController
    site_b = connect(deployment, deployment.station_server(destination.name)).LabwareTransferSiteController
    plate_id = plate_reading.labware_id
    plan: list[tuple[str, list[Callable[[], Any]]]] = [
        (
            "A.PrepareForOutput + Robot.PrepareForInput",
            [
                lambda: site_a.PrepareForOutput(HandoverPosition=pick, InternalPosition=1),
                lambda: robot.PrepareForInput(
                    HandoverPosition=pick, InternalPosition=1, LabwareType="", LabwareUniqueID=plate_id
                ),
            ],
        ),
        ("Robot.GetLabware", [lambda: robot.GetLabware(HandoverPosition=pick, IntermediateActions=[])]),
        ("A.LabwareRemoved", [lambda: site_a.LabwareRemoved(HandoverPosition=pick)]),
        (
            "B.PrepareForInput + Robot.PrepareForOutput",
            [
                lambda: site_b.PrepareForInput(
                    HandoverPosition=place, InternalPosition=1, LabwareType="", LabwareUniqueID=plate_id
                ),
                lambda: robot.PrepareForOutput(HandoverPosition=place, InternalPosition=1),
            ],
        ),
        ("Robot.PutLabware", [lambda: robot.PutLabware(HandoverPosition=place, IntermediateActions=[])]),
        ("B.LabwareDelivered", [lambda: site_b.LabwareDelivered(HandoverPosition=place)]),
    ]
    progress_line = ProgressLine(progress_stream)
    wall_start, sim_start = time.monotonic(), link.robot_status().stamp_s
    try:
        for step, commands in plan:
            step_wall, step_sim = time.monotonic(), link.robot_status().stamp_s
            run_commands(commands, step, progress_line)
            timing = StepTiming(step, link.robot_status().stamp_s - step_sim, time.monotonic() - step_wall)
            report.steps.append(timing)
            progress_line.done(step, timing.wall_seconds, timing.sim_seconds)
    except Exception as error:  # noqa: BLE001 - the report says what failed; exit code follows
        report.error = f"{type(error).__name__}: {error}"
        if progress_stream is not None:
            progress_stream.write(f"\nfailed: {report.error}\n")
    report.wall_seconds = time.monotonic() - wall_start
    report.sim_seconds = link.robot_status().stamp_s - sim_start
    placement = link.check_placement(plate_id, free_nest)
    report.success = placement.in_nest and not report.error
    if placement.found:
        report.plate_position_error_mm = 1000.0 * placement.position_error_m
        report.plate_yaw_error_deg = math.degrees(placement.yaw_error_rad)
    if not placement.in_nest and not report.error:
        report.error = misplacement(free_nest, placement)
    return report


# Starts every error of a transfer whose commands succeeded but whose plate physics finds misplaced.
MISPLACED = "physics check: "


def misplacement(destination: Nest, placement: PlacementCheck) -> str:
    """Why the physics check refused a delivery the commands reported as done."""
    if placement.location != destination:
        return f"{MISPLACED}the plate is not in {destination}; it is at {location_text(placement.location)}"
    return (
        f"{MISPLACED}the plate rests in {destination} but outside the nest's tolerance: "
        f"{placement.outside or 'limit not reported'} ({1000.0 * placement.position_error_m:.1f} mm "
        f"from the centre, yaw {math.degrees(placement.yaw_error_rad):.1f} deg)"
    )
