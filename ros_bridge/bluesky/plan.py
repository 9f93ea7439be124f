"""The beamline paper's plan with our robot: fetch the sample, measure it, bring it back.

    pickup -> place -> stage to measure position -> trigger and read detector (with the robot)
    -> stage back to load position -> return_pickup -> return_place

Everything happens inside one run. After every robot task the robot is read into the "robot"
event stream (state, carried labware, base pose), so the documents show where the plate went;
the measurement goes to the "primary" stream together with the robot's and the stage's readings.
"""

from __future__ import annotations

from collections.abc import Generator
from typing import Any

from bluesky import plan_stubs as bps
from bluesky import preprocessors as bpp
from bluesky.utils import Msg

from ros_bridge.bluesky.device import LabwareTransferRobot, TransferTask

ROBOT_STREAM = "robot"


def robot_task(robot: LabwareTransferRobot, task: TransferTask) -> Generator[Msg, Any, None]:
    """Run one robot task to its end, then record the robot's state in the "robot" stream."""
    yield from bps.abs_set(robot, task, wait=True)
    yield from bps.trigger_and_read([robot], name=ROBOT_STREAM)


def sample_exchange_plan(
    robot: LabwareTransferRobot,
    stage: Any,
    detector: Any,
    *,
    measure_position: float,
    load_position: float,
    md: dict[str, Any] | None = None,
) -> Generator[Msg, Any, None]:
    """Bring the plate to the beam, measure with the stage at `measure_position`, put it back."""
    metadata = {
        "plan_name": "sample_exchange_plan",
        "labware_id": robot.labware_id.get(),
        "storage_site": robot.storage_site.get(),
        "beam_site": robot.beam_site.get(),
        "detectors": [detector.name],
        "motors": [stage.name],
        **(md or {}),
    }

    @bpp.run_decorator(md=metadata)
    def inner() -> Generator[Msg, Any, None]:
        yield from robot_task(robot, TransferTask.PICKUP)
        yield from robot_task(robot, TransferTask.PLACE)
        yield from bps.mv(stage, measure_position)
        yield from bps.trigger_and_read([detector, stage, robot])
        yield from bps.mv(stage, load_position)
        yield from robot_task(robot, TransferTask.RETURN_PICKUP)
        yield from robot_task(robot, TransferTask.RETURN_PLACE)

    yield from inner()
