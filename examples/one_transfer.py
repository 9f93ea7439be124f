"""One plate from one station to another, through the robot, as a scheduler would send it.

Start the servers first (`./run serve`, or `sila-labware serve`), then:

    python examples/one_transfer.py --source station_a/1 --destination station_b/1 --plate plate_001

The robot drives to the source, takes the plate, drives to the destination, puts it down, and
docks. Progress is printed per step; a failure ends the script with the server's reason.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from sila_labware.client import LabwareTransferError
from sila_labware.client.console import (
    StepPrinter,
    add_connection_arguments,
    client_from_arguments,
    handover,
)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_connection_arguments(parser)
    parser.add_argument("--source", type=handover, default="station_a/1", metavar="STATION/N")
    parser.add_argument("--destination", type=handover, default="station_b/1", metavar="STATION/N")
    parser.add_argument("--plate", default="plate_001", help="the plate's id (announced to both devices)")
    args = parser.parse_args(argv)

    try:
        with client_from_arguments(args) as robot:
            print(f"moving {args.plate} from {args.source} to {args.destination}")
            robot.transfer(args.source, args.destination, labware_id=args.plate, on_progress=StepPrinter())
            where = robot.locate(args.plate)
            print(f"the robot's inventory has {args.plate} at {where.location}")
            print("docking")
            robot.dock(on_progress=StepPrinter())
    except LabwareTransferError as error:
        print(f"failed: {type(error).__name__}: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
