"""The beamline paper's sample exchange, as a Bluesky plan driving the robot over ROS 2.

Bluesky talks to the robot side directly (its ROS 2 actions), not through SiLA: the plan fetches
the plate from its storage nest to the beam nest, measures it with a stage and a detector
(simulated here by ophyd.sim), and brings it back. Start the robot side first (`sila-labware
serve` prints its ROS domain), then:

    python examples/bluesky_exchange.py --domain-id 42 --storage station_a/1 --beam station_b/1

Runs in the robot side's ROS domain and, as the robot side does, on this machine only.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from typing import Any

from bluesky import RunEngine
from bluesky.utils import RunEngineInterrupted
from ophyd.sim import SynAxis, SynGauss

from ros_bridge.bluesky import LabwareTransferRobot, sample_exchange_plan
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime
from sila_labware.client.console import handover

MEASURE_POSITION_M = 0.26  # the beamline paper moved its stage by 26 cm
LOAD_POSITION_M = 0.0


def print_robot_events(name: str, document: dict[str, Any]) -> None:
    """A RunEngine subscriber: one line per robot reading and per measurement."""
    if name == "event":
        data = document["data"]
        if "detector" in data:
            print(f"measured: detector {data['detector']:.0f} at stage {data['stage']:.2f} m")
        else:
            task, state = data.get("robot_last_task", "?"), data.get("robot_state", "?")
            carrying = data.get("robot_carried_labware") or "nothing"
            print(f"after {task}: robot {state}, carrying {carrying}")
    elif name == "stop":
        print(f"run {document['exit_status']}")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--domain-id", type=int, required=True, help="the robot side's ROS domain")
    parser.add_argument("--storage", type=handover, default="station_a/1", metavar="STATION/N")
    parser.add_argument("--beam", type=handover, default="station_b/1", metavar="STATION/N")
    parser.add_argument("--plate", default="plate_001")
    parser.add_argument("--hotel-slot", type=int, default=1, help="the robot's slot that carries the plate")
    args = parser.parse_args(argv)

    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")  # as the robot side's nodes
    runtime = RosRuntime(node_name="bluesky_example", domain_id=args.domain_id).start()
    try:
        link = RobotLink(runtime)
        link.wait_until_ready(60.0)
        robot = LabwareTransferRobot(
            link,
            storage=args.storage,
            beam=args.beam,
            labware_id=args.plate,
            hotel_slot=args.hotel_slot,
            name="robot",
        )
        stage = SynAxis(name="stage", value=LOAD_POSITION_M)
        detector = SynGauss("detector", stage, "stage", center=MEASURE_POSITION_M, Imax=1e5, sigma=0.05)
        print(f"exchanging {args.plate}: storage {robot.storage}, beam {robot.beam}")
        engine = RunEngine({})
        engine.subscribe(print_robot_events)
        plan = sample_exchange_plan(
            robot, stage, detector, measure_position=MEASURE_POSITION_M, load_position=LOAD_POSITION_M
        )
        try:
            engine(plan)
        except RunEngineInterrupted:  # Ctrl-C paused the run: end it, which cancels the robot's goal
            engine.abort("interrupted")
            raise
    except Exception as error:  # noqa: BLE001 - one line for the person at the terminal
        reason: BaseException = error
        while reason.__cause__ is not None:  # a failed robot task arrives wrapped in FailedStatus
            reason = reason.__cause__
        print(f"failed: {type(reason).__name__}: {reason}", file=sys.stderr)
        return 1
    finally:
        runtime.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
