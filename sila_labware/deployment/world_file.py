"""`sila-labware world check FILE [--png OUT]`, and the same check before `serve`, `demo` and `bench`.

Why a child process: the world file belongs to the robot side (lab_description reads it), and the
SiLA side imports nothing of the simulation (tests/test_architecture.py); it starts the robot
side's modules as processes already. Checking before anything starts gives the technician every
problem of the file at once, in the words of `world check`, instead of the first one after the
robot side refused it.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

from sila_labware.deployment.child_check import check_problems

WORLD_CHECK_MODULE = "tiago_sim.inspection.world_check"


def add_world_command(subcommands: argparse._SubParsersAction, parser_class: type) -> None:
    """`world check FILE [--png OUT]`."""
    world = subcommands.add_parser("world", help="check a world file, draw its floor plan")
    actions = world.add_subparsers(
        dest="world_command", required=True, metavar="{check}", parser_class=parser_class
    )
    check = actions.add_parser(
        "check",
        help="validate a world file (exit 0, or 1 listing every problem) and print what it holds",
    )
    check.add_argument("file", type=Path, help="the world YAML")
    check.add_argument("--png", type=Path, default=None, metavar="OUT", help="also draw it top-down into OUT")


def world_command(args: argparse.Namespace) -> int:
    """Run `world check` with this terminal: its table on stdout, its problems on stderr."""
    arguments = [str(args.file)] + ([] if args.png is None else ["--png", str(args.png)])
    return subprocess.run([sys.executable, "-m", WORLD_CHECK_MODULE, *arguments], check=False).returncode


def world_problems(world: Path) -> list[str]:
    """Every problem `world check` finds in the file, one line each (`file: field: problem`)."""
    return check_problems(WORLD_CHECK_MODULE, [str(world)])
