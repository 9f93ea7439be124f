"""`--pace X`: run the simulation at X times real time, busy and idle alike.

Why both: the sim node paces motion (`--realtime-factor-cap`) and the pauses between motions
(`--idle-realtime-factor`) separately; with one pace for both, a transfer's wall time matches its
simulated time divided by the pace, and a client sees a robot that keeps a real robot's timing
(pace 1) or a steady multiple of it. Without a pace the simulation moves as fast as the machine
allows and idles at real time, as before.
"""

from __future__ import annotations

import argparse

MAX_PACE = 1000.0
"""Beyond this the sleeps that pace the simulation are shorter than its steps: no pace at all."""


def add_pace_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--pace",
        type=float,
        default=None,
        metavar="X",
        help="run the simulation at X times real time, 0 < X <= 1000 (1.0: a real robot's timing; "
        "default: as fast as the machine allows)",
    )


ROS_ADAPTER_MAX_PACE = 10.0
"""Over the robot's own interfaces the skills renew velocity commands on the wall clock, and each
lapses after 0.5 s of robot time (tiago_ros_hardware.base_loops): at most ten times real time."""


def add_ros_adapter_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--ros-adapter",
        action="store_true",
        help="the skills reach the simulated robot through a TIAGo++'s own ROS 2 interfaces, as they "
        "would a real one (paced at 5 times real time unless --pace says otherwise, "
        f"at most {ROS_ADAPTER_MAX_PACE:g})",
    )


def add_sensor_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--stock-sensors",
        action="store_true",
        help="the lab has none of the lab-added plate sensors (nests, hotel pockets, label readers), as "
        "with a stock TIAGo++: the robot checks nests with its head camera and its hotel with its "
        "fingers (overrides the world file's `sensors`)",
    )


def add_robot_arguments(parser: argparse.ArgumentParser) -> None:
    """How the simulated robot runs for serve and demo: its pace, its adapter, its sensors."""
    add_pace_argument(parser)
    add_ros_adapter_argument(parser)
    add_sensor_argument(parser)


def pace_problem(pace: float | None, ros_adapter: bool = False) -> str | None:
    """Why `pace` is no usable pace (None: it is, or none was asked for)."""
    if pace is None:
        return None
    if ros_adapter and pace > ROS_ADAPTER_MAX_PACE:
        return f"--ros-adapter runs at --pace {ROS_ADAPTER_MAX_PACE:g} at most, not {pace:g}"
    if not 0.0 < pace <= MAX_PACE:  # also refuses nan
        return f"--pace {pace:g} is outside 0 < X <= {MAX_PACE:g}"
    return None


def sim_pace_arguments(pace: float | None) -> list[str]:
    """The sim node's arguments for `pace` (none: its defaults, unpaced motion)."""
    if pace is None:
        return []
    return ["--realtime-factor-cap", repr(pace), "--idle-realtime-factor", repr(pace)]
