"""How long each kind of step takes, in robot (simulated) seconds: what progress and remaining time rest on.

Why learned: the fixed table per action (`estimates_s` in sequencer.yaml) was 2 to 10 times too
long (a gripper step 1.5 s for 0.15 s, a drive 20 s for 7 to 10 s), so at 1x real time a client was
told 21 s remained of 7 s. A step's duration depends on what it does (a final approach against a
tool move, which POI a drive goes to), so each step kind keeps its own estimate: the table's
value until the kind has run once, then a running average of what it took. Pure Python; lives on
the sequencer's executor thread.
"""

from __future__ import annotations

from collections.abc import Mapping

from tiago_sim.sequencer.plans import Step

DETAIL_KEYS = ("target", "motion_name", "command", "poi")  # what makes two steps of one action differ
WEIGHT_OF_NEWEST = 0.5
FALLBACK_S = 3.0  # an action the table does not name


def step_kind(step: Step) -> str:
    """The step's action and what it does, e.g. "marker_motion:work_pose", "navigate:station_b_work"."""
    details = [str(step.goal[key]) for key in DETAIL_KEYS if key in step.goal]
    return ":".join([step.action, *details])


class StepDurations:
    """Estimated duration per step kind: the table first, then what the kind took."""

    def __init__(self, table: Mapping[str, float]) -> None:
        self.table = dict(table)
        self.learned: dict[str, float] = {}

    def estimate(self, step: Step) -> float:
        seconds = self.learned.get(step_kind(step), self.table.get(step.action, FALLBACK_S))
        return max(float(seconds), 0.1)

    def record(self, step: Step, seconds: float) -> None:
        """A step of this kind ended successfully after `seconds` of robot time."""
        if seconds < 0:
            return  # the robot's clock started anew (a restarted robot side)
        kind = step_kind(step)
        before = self.learned.get(kind)
        self.learned[kind] = seconds if before is None else before + WEIGHT_OF_NEWEST * (seconds - before)
