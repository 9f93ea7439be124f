"""Two plates in one trip: both picked into the robot's two internal positions, then both placed.

The robot carries plates in its hotel slots (the standard's internal positions), so it can collect
several before delivering them: a pick is the first half of the standard transfer (source
PrepareForOutput with robot PrepareForInput, GetLabware, LabwareRemoved), a place the second.

    python examples/batch_two_plates.py \\
        --move station_a/1 station_b/1 plate_001 --move station_a/2 station_b/2 plate_002

needs a world with two plates on station_a (the bundled world has one).
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
    parser.add_argument(
        "--move", nargs=3, action="append", required=True, metavar=("SOURCE", "DESTINATION", "PLATE"),
        help="one plate from STATION/N to STATION/N; repeat, up to the robot's internal positions",
    )  # fmt: skip
    args = parser.parse_args(argv)
    moves = []
    for source, destination, plate in args.move:
        try:
            moves.append((handover(source), handover(destination), plate))
        except argparse.ArgumentTypeError as error:
            parser.error(str(error))

    try:
        with client_from_arguments(args) as robot:
            if len(moves) > robot.internal_positions():
                parser.error(f"the robot carries at most {robot.internal_positions()} plates")
            # internal positions (hotel slots) are numbered from 1: plate k rides in position k
            for slot, (source, _, plate) in enumerate(moves, start=1):
                print(f"picking {plate} from {source} into internal position {slot}")
                robot.pick(source, internal_position=slot, labware_id=plate, on_progress=StepPrinter())
            for item in robot.onboard_labware():
                print(f"on board: {item.labware_id} in internal position {item.internal_position}")
            for slot, (_, destination, plate) in enumerate(moves, start=1):
                print(f"placing {plate} from internal position {slot} into {destination}")
                robot.place(destination, internal_position=slot, on_progress=StepPrinter())
    except LabwareTransferError as error:
        print(f"failed: {type(error).__name__}: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
