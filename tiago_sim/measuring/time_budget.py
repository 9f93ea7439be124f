"""Where a transfer's time goes: each step's robot time against the least time TIAGo++'s limits allow.

    python -m tiago_sim.measuring.time_budget LOG_DIR
    python -m tiago_sim.measuring.benchmark --seed 1 --budget    (runs a transfer, then prints this)

Reads the logs of a one-transfer benchmark run (LOG_DIR holds tiago_twin.log and sequencer.log).
Per robot goal, the skills' action servers log what moved (odometry, the believed pose in the map,
the joints that changed) and the goal's simulated span; the navigation stand-in logs the path it
planned; the sequencer logs each step's kind. Why from the logs: the minimum must come from what the
robot actually moved, and a benchmark run already keeps these lines. The minima are in
budget_minima.
"""

from __future__ import annotations

import argparse
import logging
import math
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

from tiago_description.robot_limits import active_limits
from tiago_sim.measuring.benchmark import GOAL_LINE
from tiago_sim.measuring.budget_minima import (
    drive_min_s,
    gripper_min_s,
    joint_move_min_s,
    split_joints,
)

log = logging.getLogger(__name__)

_NUMBER = r"(-?[\d.]+(?:e-?\d+)?|nan)"
_POSE = rf"\({_NUMBER}, {_NUMBER}, {_NUMBER}\)"
MOVED_LINE = re.compile(
    rf"tiago_skills\.action_servers: (/\w+) moved: odometry {_POSE} -> {_POSE}; "
    rf"map {_POSE} -> {_POSE}; joints (.*)$"
)
JOINT_MOVE = re.compile(rf"(\w+) {_NUMBER}>{_NUMBER}")
PLAN_LINE = re.compile(r"tiago_sim\.sim_node\.navigation: plan: \d+ waypoints, [\d.]+ m, [\d.]+ ms: (.*)$")
PLAN_POINT = re.compile(rf"\({_NUMBER}, {_NUMBER}\)")
STEP_KIND = re.compile(r"tiago_sim\.sequencer\.step_durations: (\S+) took")
BASE_MOVED_M = 0.001  # odometry that changed less than this (and BASE_TURNED_RAD) is a base at rest
BASE_TURNED_RAD = 0.001
JOINT_AT_REST = 0.01  # rad (m for the torso): half the trajectory controller's settle tolerance
FINGER_AT_REST = 0.002  # m: a held plate presses the fingers open by about a millimetre
SNAP_M = 0.02  # a plan's first and last points lie this close to where the base stood (cm rounding)

Pose = tuple[float, float, float]


@dataclass
class Goal:
    """One robot goal as the logs record it."""

    action: str
    start_s: float
    end_s: float
    no_motion_s: float
    odometry: tuple[Pose, Pose] | None = None
    believed: tuple[Pose, Pose] | None = None
    joints: dict[str, tuple[float, float]] = field(default_factory=dict)
    plans: list[list[tuple[float, float]]] = field(default_factory=list)


@dataclass(frozen=True)
class Row:
    """One step of the budget: what it took, the least it could take, and why."""

    step: str
    took_s: float
    min_s: float
    no_motion_s: float
    moved: str


def parse_goals(robot_log: str) -> list[Goal]:
    """Every goal of the robot side's log, in order, with what it moved and the paths planned in it."""
    goals: list[Goal] = []
    moved: re.Match[str] | None = None
    plans: list[list[tuple[float, float]]] = []
    for line in robot_log.splitlines():
        if match := PLAN_LINE.search(line):
            plans.append([(float(x), float(y)) for x, y in PLAN_POINT.findall(match[1])])
        elif match := MOVED_LINE.search(line):
            moved = match
        elif match := GOAL_LINE.search(line):
            goal = Goal(match[1], float(match[2]), float(match[3]), float(match[4]), plans=plans)
            if moved is not None and moved[1] == goal.action:
                _add_motion(goal, moved)
            goals.append(goal)
            moved, plans = None, []
    return goals


def _add_motion(goal: Goal, moved: re.Match[str]) -> None:
    numbers = [float(value) for value in moved.groups()[1:13]]
    poses = [tuple(numbers[i : i + 3]) for i in range(0, 12, 3)]
    goal.odometry, goal.believed = (poses[0], poses[1]), (poses[2], poses[3])  # type: ignore[assignment]
    goal.joints = {name: (float(a), float(b)) for name, a, b in JOINT_MOVE.findall(moved[14])}


def step_kinds(sequencer_log: str) -> list[str]:
    """The sequencer's step kinds ("GetLabware:play_motion:Tuck:arm_tucked"), in order."""
    return [match[1] for line in sequencer_log.splitlines() if (match := STEP_KIND.search(line))]


def goal_minimum(goal: Goal) -> tuple[float, str]:
    """The least time for what the goal moved, and what that was with each part's minimum.

    The base's drive, the trajectory joints (arms, torso, head) as one move and the fingers are
    separate actuators that could all move at once, so the slowest of the three sets the minimum;
    doing them one after the other is slack the table shows. A joint that changed by less than
    JOINT_AT_REST (FINGER_AT_REST) over the goal held still: position control settles within the
    controller's tolerance, not on the spot."""
    if goal.odometry is None:
        return math.nan, "no readings"
    parts: list[tuple[float, str]] = []
    drive = _drive(goal)
    if drive is not None:
        drive_s, length, turned = drive
        parts.append((drive_s, f"base {length:.2f} m, {math.degrees(turned):.0f} deg"))
    joints, fingers = split_joints({name: b - a for name, (a, b) in goal.joints.items()})
    moved = {name: change for name, change in joints.items() if abs(change) >= JOINT_AT_REST}
    move_s, slowest = joint_move_min_s(dict.fromkeys(moved, 0.0), moved, active_limits().joint_velocity)
    if slowest:
        unit = "m" if slowest.startswith("torso") else "rad"
        parts.append((move_s, f"{slowest} {abs(moved[slowest]):.2f} {unit} of {len(moved)} joints"))
    travel = {name: change for name, change in fingers.items() if abs(change) >= FINGER_AT_REST}
    if travel:
        travel_m = max(abs(change) for change in travel.values())
        parts.append((gripper_min_s(dict.fromkeys(travel, 0.0), travel), f"fingers {travel_m * 1000:.0f} mm"))
    if not parts:
        return 0.0, "nothing"
    return max(seconds for seconds, _ in parts), "; ".join(
        f"{what} ({seconds:.2f} s)" for seconds, what in parts
    )


def _drive(goal: Goal) -> tuple[float, float, float] | None:
    """The drive's minimum (s, m, rad) if the wheels turned: along the last planned path in the
    map when the goal planned one, else straight from the start to the end in odometry."""
    assert goal.odometry is not None and goal.believed is not None
    (x0, y0, yaw0), (x1, y1, yaw1) = goal.odometry
    if math.hypot(x1 - x0, y1 - y0) < BASE_MOVED_M and abs(yaw1 - yaw0) < BASE_TURNED_RAD:
        return None
    if not goal.plans:
        return drive_min_s([(x0, y0), (x1, y1)], yaw0, yaw1)
    (bx0, by0, byaw0), (bx1, by1, byaw1) = goal.believed
    plan = list(goal.plans[-1])
    if math.hypot(plan[0][0] - bx0, plan[0][1] - by0) < SNAP_M:
        plan = plan[1:]
    if plan and math.hypot(plan[-1][0] - bx1, plan[-1][1] - by1) < SNAP_M:
        plan = plan[:-1]
    return drive_min_s([(bx0, by0), *plan, (bx1, by1)], byaw0, byaw1)


def budget(goals: list[Goal], kinds: list[str]) -> list[Row]:
    """A row per goal, named by the sequencer's step kind where the counts agree."""
    if len(kinds) != len(goals):
        log.warning("%d goals, %d sequencer steps: rows named by action", len(goals), len(kinds))
        kinds = [goal.action.lstrip("/") for goal in goals]
    rows = []
    for kind, goal in zip(kinds, goals, strict=True):
        min_s, moved = goal_minimum(goal)
        rows.append(Row(kind, goal.end_s - goal.start_s, min_s, goal.no_motion_s, moved))
    return rows


def format_table(rows: list[Row], goals: list[Goal]) -> str:
    """The budget as a Markdown table, with the time between goals and the totals last."""
    lines = [
        "| step | took s | minimum s | slack s | no motion s | what moved (slowest joint) |",
        "|---|---:|---:|---:|---:|---|",
    ]
    for row in rows:
        lines.append(
            f"| {row.step} | {row.took_s:.2f} | {row.min_s:.2f} | {row.took_s - row.min_s:.2f} "
            f"| {row.no_motion_s:.2f} | {row.moved} |"
        )
    between = sum(b.start_s - a.end_s for a, b in zip(goals[:-1], goals[1:], strict=True))
    lines.append(f"| between goals | {between:.2f} | 0.00 | {between:.2f} | {between:.2f} | |")
    took = sum(row.took_s for row in rows) + between
    least = sum(row.min_s for row in rows)
    idle = sum(row.no_motion_s for row in rows) + between
    lines.append(f"| **all** | {took:.2f} | {least:.2f} | {took - least:.2f} | {idle:.2f} | |")
    return "\n".join(lines)


def report(log_dir: Path) -> str:
    """The budget table of one benchmark run's logs."""
    goals = parse_goals((log_dir / "tiago_twin.log").read_text())
    kinds = step_kinds((log_dir / "sequencer.log").read_text())
    return format_table(budget(goals, kinds), goals)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m tiago_sim.measuring.time_budget", description=__doc__.split("\n")[0]
    )
    parser.add_argument("log_dir", type=Path, help="a benchmark run's log directory")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    print(report(args.log_dir))
    return 0


if __name__ == "__main__":
    sys.exit(main())
