"""The robot's speed and acceleration limits: one configuration, the one a lab sets for its robot.

Why: a lab runs its TIAGo++ with the limits its navigation (Nav2's velocity smoother) and its
controllers (ros2_control's joint limits) are set to, often below the hardware's. The simulator's base
and controllers, the ROS adapter's timing of a trajectory, the navigation's time estimates and the
time budget's minima all take them from here, so a lab that lowers a limit sees every one of them
follow, and no step can be judged against limits the robot did not run with. The hardware's own
limits (the robot model: the URDF's joint velocities, the base's maxima) bound what a file may set.

`robot_limits.yaml` beside this module is the robot as shipped. Another file is chosen with the CLI's
`--robot-limits FILE`, which sets $SILA_LABWARE_ROBOT_LIMITS for every process it starts;
`active_limits()` reads that once per process. Pure data; any thread.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import yaml

from tiago_description import robot_model as rm
from tiago_description.joint_limits import velocity_limits as hardware_velocity_limits

DEFAULT_LIMITS_FILE = Path(__file__).with_name("robot_limits.yaml")
ENVIRONMENT_VARIABLE = "SILA_LABWARE_ROBOT_LIMITS"
SIDES = ("left", "right")
HARDWARE_BASE = {
    "linear speed": rm.MAX_LINEAR_SPEED,
    "angular speed": rm.MAX_ANGULAR_SPEED,
    "linear acceleration": rm.MAX_LINEAR_ACCEL,
    "angular acceleration": rm.MAX_ANGULAR_ACCEL,
}


class RobotLimitsError(ValueError):
    """A limits file that cannot be used; the message names the file, the field and why."""


@dataclass(frozen=True)
class RobotLimits:
    """The base's limits (m/s, rad/s, m/s^2, rad/s^2) and every joint's velocity limit (rad/s; m/s for
    the torso and the fingers)."""

    linear_speed: float
    angular_speed: float
    linear_accel: float
    angular_accel: float
    joint_velocity: Mapping[str, float]

    @property
    def finger_speed(self) -> float:
        """The slower of the fingers (the gripper command moves them together)."""
        return min(speed for name, speed in self.joint_velocity.items() if name.startswith("gripper_"))

    @property
    def torso_speed(self) -> float:
        return self.joint_velocity["torso_lift_joint"]


def _number(value: Any, where: str, hardware: float) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise RobotLimitsError(f"{where}: {value!r} is not a number")
    if not 0.0 < float(value) <= hardware + 1e-9:
        raise RobotLimitsError(f"{where}: {value} is outside 0 .. {hardware:g}, the hardware's limit")
    return float(value)


def _base(raw: Any, where: str) -> tuple[float, float, float, float]:
    if raw is None:  # left out: the hardware's
        return rm.MAX_LINEAR_SPEED, rm.MAX_ANGULAR_SPEED, rm.MAX_LINEAR_ACCEL, rm.MAX_ANGULAR_ACCEL
    if not isinstance(raw, Mapping):
        raise RobotLimitsError(f"{where}: base: expected max_velocity and max_accel")
    values = []
    for key, names in (("max_velocity", ("linear speed", "angular speed")),
                       ("max_accel", ("linear acceleration", "angular acceleration"))):  # fmt: skip
        triple = raw.get(key)
        if not isinstance(triple, list) or len(triple) != 3:
            raise RobotLimitsError(
                f"{where}: base.{key}: expected [x, y, theta], as Nav2's velocity_smoother"
            )
        for index, name in zip((0, 2), names, strict=True):
            values.append(
                _number(triple[index], f"{where}: base.{key}[{index}] ({name})", HARDWARE_BASE[name])
            )
    linear_speed, angular_speed, linear_accel, angular_accel = values
    return linear_speed, angular_speed, linear_accel, angular_accel


def _joints(raw: Any, where: str) -> dict[str, float]:
    hardware = hardware_velocity_limits()
    limits = dict(hardware)
    if raw is None:
        return limits
    if not isinstance(raw, Mapping):
        raise RobotLimitsError(
            f"{where}: joint_limits: expected a joint name -> {{max_velocity: ...}} mapping"
        )
    for pattern, entry in raw.items():
        names = [pattern.format(side=side) for side in SIDES] if "{side}" in pattern else [pattern]
        unknown = [name for name in names if name not in hardware]
        if unknown:
            raise RobotLimitsError(f"{where}: joint_limits.{pattern}: the robot has no joint {unknown[0]}")
        if not isinstance(entry, Mapping) or "max_velocity" not in entry:
            raise RobotLimitsError(f"{where}: joint_limits.{pattern}: expected {{max_velocity: ...}}")
        for name in names:
            limits[name] = _number(entry["max_velocity"], f"{where}: joint_limits.{pattern}", hardware[name])
    return limits


def load_limits(path: Path = DEFAULT_LIMITS_FILE) -> RobotLimits:
    """The limits a file sets, checked against the hardware's; RobotLimitsError naming what is wrong."""
    try:
        raw = yaml.safe_load(Path(path).read_text())
    except OSError as error:
        raise RobotLimitsError(f"{path}: cannot be read ({error.strerror})") from None
    except yaml.YAMLError as error:
        raise RobotLimitsError(f"{path}: not YAML ({error})") from None
    if not isinstance(raw, Mapping):
        raise RobotLimitsError(f"{path}: expected a mapping with base and joint_limits")
    extra = set(raw) - {"base", "joint_limits"}
    if extra:
        raise RobotLimitsError(f"{path}: unknown field {sorted(extra)[0]!r} (known: base, joint_limits)")
    linear_speed, angular_speed, linear_accel, angular_accel = _base(raw.get("base"), str(path))
    return RobotLimits(
        linear_speed, angular_speed, linear_accel, angular_accel, _joints(raw.get("joint_limits"), str(path))
    )


@cache
def active_limits() -> RobotLimits:
    """This process's limits: the file $SILA_LABWARE_ROBOT_LIMITS names, else the robot as shipped.
    Read once: a process runs under one set of limits."""
    return load_limits(Path(os.environ.get(ENVIRONMENT_VARIABLE) or DEFAULT_LIMITS_FILE))


def describe(limits: RobotLimits) -> str:
    """The limits as a lab reads them back: the base's, then each joint's."""
    lines = [
        f"base: {limits.linear_speed:g} m/s, {limits.angular_speed:g} rad/s; "
        f"{limits.linear_accel:g} m/s^2, {limits.angular_accel:g} rad/s^2",
        *(f"{name}: {speed:g}" for name, speed in sorted(limits.joint_velocity.items())),
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """`python -m tiago_description.robot_limits [FILE]`: the limits a file sets (exit 0), or why it
    cannot be used (exit 1, on stderr)."""
    parser = argparse.ArgumentParser(
        prog="python -m tiago_description.robot_limits", description=__doc__.split("\n")[0]
    )
    parser.add_argument("file", type=Path, nargs="?", default=DEFAULT_LIMITS_FILE)
    args = parser.parse_args(argv)
    try:
        limits = load_limits(args.file)
    except RobotLimitsError as error:
        sys.stderr.write(f"{error}\n")
        return 1
    sys.stdout.write(describe(limits) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
