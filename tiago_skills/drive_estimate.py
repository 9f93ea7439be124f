"""How long a drive will take before it starts: the navigation stack's plan, timed as the drive
makes it (tiago_description.drive_timing).

Why: a command that undocks and then drives reported no remaining time for the drive while it
undocked; the Prepare from the dock was then never within 10 % of its duration at a real robot's
pace. The undock's remaining time now carries the drive after it (Undock's `then_poi`).
"""

from __future__ import annotations

import logging

from robot_port.types import Pose2D
from tiago_description.drive_timing import path_duration_s
from tiago_skills.goal_run import GoalRun

log = logging.getLogger(__name__)


def planned_drive_s(run: GoalRun, start: Pose2D | None, goal: Pose2D) -> float:
    """Robot seconds of the drive from `start` to `goal` (map frame) along the navigation stack's
    plan; 0 without a start or a plan (the caller then reports no time for it)."""
    path = () if start is None else run.read(lambda hardware: hardware.plan_path(start, goal))
    if not path:
        log.info("no plan from %s to %s: no time estimated for that drive", start, goal)
        return 0.0
    seconds = path_duration_s(start[2], path)
    log.info("the drive from %s to %s: %d poses, %.1f s planned", start, goal, len(path), seconds)
    return seconds
