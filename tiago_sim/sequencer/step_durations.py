"""How long each kind of step takes, in robot (simulated) seconds: what progress and remaining time rest on.

Why learned: the fixed table per action (`estimates_s` in sequencer.yaml) was 2 to 10 times too
long (a gripper step 1.5 s for 0.15 s, a drive 20 s for 7 to 10 s), so at 1x real time a client was
told 21 s remained of 7 s. A step's duration depends on what it does (a final approach against a
tool move, which POI a drive goes to), so each step kind keeps its own estimate: the table's
value until the kind has run once, then a running average of what it took. The table names step
kinds where a kind's duration does not depend on the lab (a named hotel motion, a gripper command,
a tool move into a nest), and falls back to the action's value for the rest (a drive to a POI of
this lab). Its per-kind values were measured over random layouts, not the default lab alone
(sequencer.yaml says how). Pure Python; lives on the sequencer's executor thread.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping

from tiago_sim.sequencer.plans import Step

log = logging.getLogger(__name__)

DETAIL_KEYS = ("target", "motion_name", "command", "poi")  # what makes two steps of one action differ
WEIGHT_OF_NEWEST = 0.5
FALLBACK_S = 3.0  # an action the table does not name
# ROS parameter names take no ":": the parameter "play_motion.Tuck" is the kind "play_motion:Tuck"
KIND_SEPARATOR_IN_PARAMETERS = "."


def step_kind(step: Step, task: str = "") -> str:
    """The task, the step's action, what it does and its part in the plan, e.g.
    "marker_motion:work_pose", "GetLabware:play_motion:NestApproach:retract".

    Why the task and the part (the step's phase): one motion plays different roles, and they take
    different times: NestApproach from a bench to the hotel takes seconds, out of a pocket a
    fraction of one; the approach to a nest is short from the bench pose (GetLabware) and long
    from the hotel (PutLabware)."""
    details = [str(step.goal[key]) for key in DETAIL_KEYS if key in step.goal]
    role = [step.phase.replace(" ", "_")] if step.phase else []
    return ":".join([*([task] if task else []), step.action, *details, *role])


def table_from_parameters(parameters: Mapping[str, float]) -> dict[str, float]:
    """The estimates table from sequencer.yaml's `estimates_s` keys ("navigate", "play_motion.Tuck")."""
    return {key.replace(KIND_SEPARATOR_IN_PARAMETERS, ":"): float(value) for key, value in parameters.items()}


class StepDurations:
    """Estimated duration per step kind: the table first (the kind's row, else its action's), then
    what the kind took."""

    def __init__(self, table: Mapping[str, float]) -> None:
        self.table = dict(table)
        self.learned: dict[str, float] = {}

    def estimate(self, step: Step, task: str = "") -> float:
        kind = step_kind(step, task)
        seconds = self.learned.get(kind, self.table.get(kind, self.table.get(step.action, FALLBACK_S)))
        return max(float(seconds), 0.1)

    def measured(self, step: Step, task: str = "") -> bool:
        """Whether the estimate of this kind was measured (a row of the table, or what it took)."""
        kind = step_kind(step, task)
        return kind in self.learned or kind in self.table

    def record(self, step: Step, seconds: float, task: str = "") -> None:
        """A step of this kind ended successfully after `seconds` of robot time."""
        if seconds < 0:
            return  # the robot's clock started anew (a restarted robot side)
        kind = step_kind(step, task)
        log.info("%s took %.2f s (estimated %.2f s)", kind, seconds, self.estimate(step, task))
        before = self.learned.get(kind)
        self.learned[kind] = seconds if before is None else before + WEIGHT_OF_NEWEST * (seconds - before)
