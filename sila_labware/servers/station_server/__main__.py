# Created by sila2.code_generator 0.14.0 (new-package); hand-maintained since: regeneration never touches it.
"""`python -m sila_labware.servers.station_server --station NAME`: one station's SiLA server alone."""

from __future__ import annotations

import argparse
import sys

from labware_model.workcell import WorkcellDescription
from ros_bridge.robot_link import RobotLink
from sila_labware.device.station_controller import StationController
from sila_labware.servers.standalone import run_standalone, standalone_parser

from .server import Server


def build_server(link: RobotLink, workcell: WorkcellDescription, args: argparse.Namespace) -> Server:
    station = workcell.station(args.station)
    if station is None:
        known = ", ".join(station.name for station in workcell.stations)
        raise ValueError(f"the robot side knows no station {args.station!r}; known: {known}")
    return Server(StationController(link, station))


def main(argv: list[str] | None = None) -> int:
    parser = standalone_parser("sila_labware.servers.station_server", 50053)
    parser.add_argument("--station", required=True, help="name of the station, as the world describes it")
    return run_standalone(parser, build_server, argv)


if __name__ == "__main__":
    sys.exit(main())
