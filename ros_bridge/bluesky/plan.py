"""The beamline paper's plan with our robot: fetch the sample, measure it, bring it back.

    pickup -> place -> stage to measure position -> trigger and read detector (with the robot)
    -> stage back to load position -> return_pickup -> return_place

Everything happens inside one run. After every robot task the robot is read into the "robot"
event stream (state, carried labware, base pose), so the documents show where the plate went;
the measurement goes to the "primary" stream together with the robot's and the stage's readings.
`robot_task_plan` runs one robot task as a run of its own, for a queue that interleaves the
robot's tasks with other plans (fetch, then any measurement, then return).

Annotations are objects, not strings (no `from __future__ import annotations` here), and devices
are annotated with bluesky's protocols: bluesky-queueserver reads each plan's signature to build
the model it validates queued plans with, and refused the plan for a string annotation
("'Model' is not fully defined"); `Movable` and `Readable` tell it which of its devices a name
given in a queued plan may stand for. The robot must be a `LabwareTransferRobot`.
"""

from collections.abc import Generator
from typing import Any, Literal

from bluesky import plan_stubs as bps
from bluesky import preprocessors as bpp
from bluesky.protocols import Movable, Readable
from bluesky.utils import Msg

from ros_bridge.bluesky.device import TransferTask

ROBOT_STREAM = "robot"
TaskName = Literal["pickup", "place", "return_pickup", "return_place"]
"""The robot's tasks by name, as a queued plan gives them: `TransferTask`'s values (tested)."""


def robot_task(robot: Movable, task: TaskName) -> Generator[Msg, Any, None]:
    """Run one robot task to its end, then record the robot's state in the "robot" stream
    (a part of a run: use it inside a plan that opened one)."""
    yield from bps.abs_set(robot, TransferTask(task), wait=True)
    yield from bps.trigger_and_read([robot], name=ROBOT_STREAM)


def robot_task_plan(
    robot: Movable, task: TaskName, *, md: dict[str, Any] | None = None
) -> Generator[Msg, Any, None]:
    """One robot task (pickup, place, return_pickup or return_place) as a run of its own."""
    metadata = {"plan_name": "robot_task_plan", "task": str(task), **_robot_metadata(robot), **(md or {})}

    @bpp.run_decorator(md=metadata)
    def inner() -> Generator[Msg, Any, None]:
        yield from robot_task(robot, task)

    yield from inner()


def sample_exchange_plan(
    robot: Movable,
    stage: Movable,
    detector: Readable,
    *,
    measure_position: float,
    load_position: float,
    md: dict[str, Any] | None = None,
) -> Generator[Msg, Any, None]:
    """Bring the plate to the beam, measure with the stage at `measure_position`, put it back."""
    metadata = {
        "plan_name": "sample_exchange_plan",
        **_robot_metadata(robot),
        "detectors": [detector.name],
        "motors": [stage.name],
        **(md or {}),
    }

    @bpp.run_decorator(md=metadata)
    def inner() -> Generator[Msg, Any, None]:
        yield from robot_task(robot, "pickup")
        yield from robot_task(robot, "place")
        yield from bps.mv(stage, measure_position)
        yield from bps.trigger_and_read([detector, stage, robot])
        yield from bps.mv(stage, load_position)
        yield from robot_task(robot, "return_pickup")
        yield from robot_task(robot, "return_place")

    yield from inner()


def _robot_metadata(robot: Any) -> dict[str, Any]:
    """Which plate the run moves, from where, to where (the robot's configuration)."""
    return {
        "labware_id": robot.labware_id.get(),
        "storage_site": robot.storage_site.get(),
        "beam_site": robot.beam_site.get(),
    }
