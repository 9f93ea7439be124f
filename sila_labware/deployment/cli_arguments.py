"""The options `sila-labware` commands share: the robot side's, and the SiLA servers' on top.

Why one place: `serve`, `demo` and `bench` start the whole stack, `bluesky-demo` the robot side
alone; each command's options must mean the same, and `_validate` in the CLI reads the same
attribute names whichever command parsed them (a command without SiLA gets their defaults).
"""

from __future__ import annotations

import argparse
from pathlib import Path

DEFAULT_PORT_BASE = 50052


def add_robot_side_arguments(sub: argparse.ArgumentParser, default_world: Path) -> None:
    """The robot side's options alone (`bluesky-demo`: no SiLA servers to bind or name)."""
    _add_robot_side(sub, default_world)
    sub.set_defaults(port_base=DEFAULT_PORT_BASE, name="")


def _add_robot_side(sub: argparse.ArgumentParser, default_world: Path) -> None:
    """World, ROS domain, logs, start-up timeout, verbosity: what every robot side needs."""
    sub.add_argument(
        "--world", type=Path, default=default_world, help="world YAML (default: the bundled lab)"
    )
    sub.add_argument(
        "--domain-id", type=int, default=None, help="ROS domain (default: $ROS_DOMAIN_ID or random)"
    )
    sub.add_argument("--log-dir", type=Path, default=None, help="write the robot side's output to files here")
    sub.add_argument("--ready-timeout", type=float, default=180.0, help="seconds to wait for the robot side")
    sub.add_argument("--verbose", action="store_true", help="log at INFO level")
    sub.add_argument(
        "--robot-limits",
        type=Path,
        default=None,
        metavar="FILE",
        help="the robot's speed and acceleration limits (default: a TIAGo++ as shipped; "
        "tiago_description/robot_limits.yaml shows the format)",
    )


def add_stack_arguments(sub: argparse.ArgumentParser, default_world: Path) -> None:
    """The robot side's options and the SiLA servers': address, TLS, discovery, the lab's name."""
    add_robot_side_arguments(sub, default_world)
    sub.add_argument(
        "--host", default="127.0.0.1", help="address the SiLA servers bind (default: %(default)s)"
    )
    sub.add_argument(
        "--port-base",
        type=int,
        default=DEFAULT_PORT_BASE,
        help="robot server port; stations follow (default: %(default)s)",
    )
    sub.add_argument("--insecure", action="store_true", help="no TLS (tests only; the standard forbids it)")
    sub.add_argument(
        "--ca-file",
        type=Path,
        default=None,
        help="where to write the CA certificate clients trust "
        "(default: ./sila-labware-ca.pem for serve; for demo and bench a temporary file, "
        "removed at the end)",
    )
    sub.add_argument("--no-discovery", action="store_true", help="do not announce the servers (mDNS)")
    sub.add_argument(
        "--name",
        default="",
        help="the lab's name, carried by every server name so that two labs on one network are told "
        "apart (default: the world file's `name`, else its file name)",
    )


def add_inventory_arguments(sub: argparse.ArgumentParser) -> None:
    """The robot side's labware inventory (labware_model.inventory): where it is kept, label checks."""
    sub.add_argument(
        "--inventory",
        type=Path,
        default=None,
        metavar="FILE",
        help="keep the robot's labware inventory (the scheduler's names for its plates) in FILE, so that "
        "it outlives this serve (default: a file of this run's own, kept across restarts of the robot side)",
    )
    sub.add_argument(
        "--label-checks",
        action="store_true",
        help="refuse a transfer whose plate's label reads other than the scheduler's LabwareUniqueID "
        "(default: transfer it and note the difference)",
    )
