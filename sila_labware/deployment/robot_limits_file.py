"""`--robot-limits FILE`: the speed and acceleration limits a lab runs its robot with.

Why here: the limits belong to the robot side (tiago_description.robot_limits reads them), which the
SiLA side does not import (tests/test_architecture.py); they reach every robot-side process through
the environment variable it reads, set here once the file has been checked in a child process, so a
wrong file is refused with its field named before anything starts.
"""

from __future__ import annotations

import os
from pathlib import Path

from sila_labware.deployment.child_check import check_problems

LIMITS_MODULE = "tiago_description.robot_limits"
ENVIRONMENT_VARIABLE = "SILA_LABWARE_ROBOT_LIMITS"  # tiago_description.robot_limits reads it


def robot_limits_problem(path: Path) -> str | None:
    """Why the limits file cannot be used, in the loader's words (None: it can)."""
    return "\n".join(check_problems(LIMITS_MODULE, [str(path)])) or None


def use_robot_limits(path: Path) -> None:
    """Every robot side this process starts from now on runs with the limits in `path`."""
    os.environ[ENVIRONMENT_VARIABLE] = str(path.resolve())
