# Created by sila2.code_generator 0.14.0 (new-package); hand-maintained since: regeneration never touches it.
"""`python -m sila_labware.servers.robot_server`: the robot's SiLA server alone.

It serves against a robot side that is already running."""

from __future__ import annotations

import argparse
import sys

from labware_model.workcell import WorkcellDescription
from ros_bridge.robot_link import RobotLink
from sila_labware.device.robot_controller import RobotController
from sila_labware.servers.standalone import run_standalone, standalone_parser

from .server import Server


def build_server(link: RobotLink, workcell: WorkcellDescription, _args: argparse.Namespace) -> Server:
    return Server(RobotController(link, workcell))


def main(argv: list[str] | None = None) -> int:
    return run_standalone(standalone_parser("sila_labware.servers.robot_server", 50052), build_server, argv)


if __name__ == "__main__":
    sys.exit(main())
