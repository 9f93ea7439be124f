"""How well the SiLA remaining times a client sees foretell each step's end.

Why: a scheduler plans on a command's estimated remaining time. The rule measured here: at each
quarter of a step's actual duration, the remaining time the client last saw (counted down since
it came) is within `TOLERANCE` of the step's whole duration from what really remained. A step is
the client's unit (one robot command, with its stations' commands beside it; its remaining time is
the longest of theirs). Wall seconds throughout, as SiLA's remaining times are.

Fed the client's progress records (`sila_labware.client.StepProgress`) as they arrive. A quarter
whose last record before it carried no estimate (or that came before any record) is a miss.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from sila_labware.client.steps import StepProgress

QUARTERS = (0.25, 0.5, 0.75)
TOLERANCE = 0.10
"""Of the step's whole duration."""
SHORTEST_JUDGED_S = 1.0
"""Steps that end sooner (a station's LabwareRemoved takes milliseconds) are not judged: they end
before a client has heard an estimate, and no plan waits on them."""


@dataclass(frozen=True)
class RemainingCheck:
    """One finished step: its wall duration and, per quarter, (reported - real) remaining time as a
    share of the duration (None: no estimate had come by then)."""

    step: str
    duration_s: float
    errors: tuple[float | None, ...]

    @classmethod
    def from_dict(cls, fields: dict[str, Any]) -> RemainingCheck:
        """From `dataclasses.asdict` of one (a campaign keeps them so, in JSON)."""
        return cls(fields["step"], fields["duration_s"], tuple(fields["errors"]))

    @property
    def judged(self) -> bool:
        return self.duration_s >= SHORTEST_JUDGED_S

    @property
    def within(self) -> bool:
        return all(error is not None and abs(error) <= TOLERANCE for error in self.errors)


class RemainingSampler:
    """An `on_progress` callback that keeps each step's records with their arrival (monotonic s)."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self._clock = clock
        self._records: dict[str, list[tuple[float, StepProgress]]] = {}
        self.checks: list[RemainingCheck] = []

    def __call__(self, record: StepProgress) -> None:
        records = self._records.setdefault(record.step, [])
        records.append((self._clock(), record))
        if record.done:
            self.checks.append(check_step(record.step, records))
            del self._records[record.step]


def check_step(step: str, records: Sequence[tuple[float, StepProgress]]) -> RemainingCheck:
    """The quarters' errors of a step from its records, the last of them its end."""
    end_at, end = records[-1]
    duration = end.elapsed_s
    start_at = end_at - duration
    errors: list[float | None] = []
    for quarter in QUARTERS:
        at = start_at + quarter * duration
        seen = [(arrived, record) for arrived, record in records[:-1] if arrived <= at]
        if not seen or seen[-1][1].remaining_s is None or duration <= 0:
            errors.append(None)  # nothing said yet, or the last word was "no estimate"
            continue
        arrived, record = seen[-1]
        assert record.remaining_s is not None
        reported = max(record.remaining_s - (at - arrived), 0.0)
        errors.append((reported - (end_at - at)) / duration)
    return RemainingCheck(step, duration, tuple(errors))


def share_within(checks: Sequence[RemainingCheck]) -> float:
    """The share of the judged steps whose every quarter is within the tolerance (0 when none is
    judged)."""
    judged = [check for check in checks if check.judged]
    return sum(check.within for check in judged) / len(judged) if judged else 0.0


NOT_JUDGED_UNPACED = (
    "unpaced: SiLA remaining times are wall time, and the robot's clock races through motions and "
    "crawls while the software computes; judge them with --pace 1"
)
"""Why an unpaced campaign's summary judges no remaining time."""


def summary(checks: Sequence[RemainingCheck]) -> dict[str, Any]:
    """The share of judged steps within the tolerance at every quarter, overall and per step name."""
    judged = [check for check in checks if check.judged]
    names = list(dict.fromkeys(check.step for check in judged))
    return {
        "tolerance": TOLERANCE,
        "quarters": list(QUARTERS),
        "shortest_judged_s": SHORTEST_JUDGED_S,
        "steps": len(judged),
        "within": sum(check.within for check in judged),
        "share_within": share_within(judged),
        "by_step": {name: share_within([check for check in judged if check.step == name]) for name in names},
    }
