"""Progress of a goal and of a command made of goals: a fraction done that never goes down.

"Progress never goes down" is written once, in `labware_model.progress.MonotonicProgress`: a goal's feedback
(`ActionGoal`) and a command's report (`CommandProgress`, which maps each of its goals into a
share of 0..1) both pass their numbers through one. A robot side that re-plans may estimate less
than before; callers (a SiLA client's progress bar, Bluesky's ProgressBar) must never see a bar
shrink, so the fraction shown stays at its highest.

Threads: both classes are thread-safe (one lock each). Goal feedback arrives on the ROS thread;
a command's own reports come from the SiLA handler thread that runs it.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass

from labware_model.progress import MonotonicProgress

RUNNING_GOAL_LEAST_REMAINING_S = 0.5
"""Wall seconds: the least remaining time a command reports while a goal of it still runs. A SiLA
client counts the last estimate down by itself and stops at 0; the robot side's next report comes
a feedback period later (more on a busy machine), so an estimate closer to 0 than that would show
a client 0 while the base still settles."""

ProgressReport = Callable[[float, float | None], None]
"""Called with (fraction done 0..1, estimated remaining time in wall seconds, or None where there
is no estimate: never 0 while work remains)."""


@dataclass(frozen=True)
class GoalProgress:
    """The latest feedback of a goal: `progress` is the fraction done (0..1, never goes down),
    `phase` the robot side's word for what it does, `remaining_time_s` its estimate (>= 0)."""

    progress: float = 0.0
    phase: str = "pending"
    remaining_time_s: float = 0.0
    feedback_count: int = 0


class CommandProgress:
    """The progress of one command that runs goals one after another, each in its share
    [start, end] of the command's 0..1 (for instance undock in 0..0.2, then drive in 0.2..1).

    Every number goes through one `MonotonicProgress`, so the command's report never goes down,
    across goals too (a later goal whose share starts lower cannot pull it back). `report` may be
    None: the command then runs without anyone watching."""

    def __init__(
        self, report: ProgressReport | None, to_wall_s: Callable[[float], float] = lambda seconds: seconds
    ) -> None:
        """`to_wall_s` turns a remaining time on the robot's clock into wall seconds (see
        `robot_pace`); by default the two clocks are one."""
        self._report = report
        self._to_wall_s = to_wall_s
        self._fraction = MonotonicProgress()
        self._lock = threading.Lock()  # keeps reports in order when two threads report at once

    @property
    def fraction(self) -> float:
        return self._fraction.fraction

    def step(
        self, start: float, end: float, *, last: bool = True, counts_rest: bool = False
    ) -> Callable[[GoalProgress], None]:
        """A feedback listener for the goal that covers [start, end] of this command. The goal's
        remaining time is the command's for its `last` goal, or for an earlier one whose robot side
        counts the goals after it too (`counts_rest`: an undock told the POI it drives to next),
        and only where the robot side gave one (a remaining time of 0 before the goal is done means
        none). An earlier goal's end leaves the command's remaining time unset until the next goal
        reports, never 0."""

        def on_goal_progress(progress: GoalProgress) -> None:
            done = progress.progress >= 1.0
            if last:
                known = progress.remaining_time_s > 0.0 or done
            else:
                known = counts_rest and progress.remaining_time_s > 0.0 and not done
            remaining = self._to_wall_s(progress.remaining_time_s) if known else None
            if remaining is not None and not done:
                remaining = max(remaining, RUNNING_GOAL_LEAST_REMAINING_S)
            self.report(start + (end - start) * progress.progress, remaining)

        return on_goal_progress

    def report(self, fraction: float, remaining_s: float | None) -> None:
        """Report the command's own fraction done and the remaining wall seconds (None: unknown)."""
        with self._lock:
            shown = self._fraction.advance(fraction)
            if self._report is not None:
                self._report(shown, None if remaining_s is None else max(0.0, remaining_s))

    def finish(self) -> None:
        """The command's work is done: report 1 with nothing remaining."""
        self.report(1.0, 0.0)
