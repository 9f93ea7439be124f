"""One step of the client's sequence: observable commands started together, awaited together.

A step is what the standard lets a scheduler send at once: the two Prepare commands of a handover
(source and destination) are one step; GetLabware alone is another (the transfer's steps are in
`sila_labware.client.sequence`). `run_step` starts every command of the step, waits until all of
them have ended, reports their combined progress, and then raises the first failure as a typed
client exception (`sila_labware.client.errors`). It does not return while a command it started
is still running, except when it gives up waiting (timeout, Ctrl-C).

Progress contract (`StepProgress`, passed to `on_progress` on the caller's thread): the first
record of a step has progress 0 and `elapsed_s` exactly 0, before any command is sent; while it
runs, a record at most every `progress_interval_s`, progress never going down; a successful step
ends with one record of progress 1 and `done` True. A failed step ends without that record (its
exception says why).

Threads: `run_step` runs on the caller's thread and polls; sila2's client threads update the
command instances it reads.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from sila_labware.client.bounded import CALL_TIMEOUT_S, bounded
from sila_labware.client.errors import StepTimeout, translate

logger = logging.getLogger(__name__)

DONE_CHECK_S = 0.02
"""The client notices a finished command within this time. Every step waits for the previous one,
and the idle robot's clock runs at real time meanwhile: polled every 0.2 s, the six steps of a
transfer lost about 0.6 s of wall and simulated time."""

PROGRESS_INTERVAL_S = 0.2
"""Progress records while a step runs come at most this often (a terminal line need not be faster)."""

DEFAULT_STEP_TIMEOUT_S = 900.0
"""The slowest step (PutLabware) takes about 20 s simulated, 3 s wall here; a step still running
after 15 minutes means a server that hangs, not a slow robot."""


@dataclass(frozen=True)
class StepProgress:
    """Where a step stands: `progress` 0..1 (its least advanced command), the longest remaining
    time any of its commands estimates (None while none does), the wall seconds since the step
    began, and whether it has ended successfully."""

    step: str
    progress: float
    remaining_s: float | None = None
    elapsed_s: float = 0.0
    done: bool = False


ProgressCallback = Callable[[StepProgress], None]


@dataclass(frozen=True)
class Command:
    """One observable command of a step: a name for messages ("Robot.GetLabware") and a callable
    that initiates it and returns sila2's command instance."""

    name: str
    start: Callable[[], Any]


def run_step(
    step: str,
    commands: Sequence[Command],
    *,
    on_progress: ProgressCallback | None = None,
    timeout_s: float = DEFAULT_STEP_TIMEOUT_S,
    progress_interval_s: float = PROGRESS_INTERVAL_S,
    stop_devices: Callable[[], None] | None = None,
) -> None:
    """Start `commands` together, wait for all of them, then raise the failure of the first
    command (in the order given) that failed, typed; the others' failures are logged.

    A command refused when it is initiated (a validation error) does not stop the others already
    started: they are awaited too, so the devices are at rest when this raises. When the wait is
    given up (the timeout, or Ctrl-C on the caller's thread), `stop_devices` is called first (the
    client stops the robot there, which does not go on by itself), then StepTimeout or the
    KeyboardInterrupt is raised. An exception raised by `on_progress` propagates likewise.
    """
    report = _Reporter(step, on_progress)
    report.started()
    started: list[tuple[Command, Any]] = []
    failures: dict[int, Exception] = {}  # by the command's place in the step
    for index, command in enumerate(commands):
        try:
            started.append((command, bounded(command.start, CALL_TIMEOUT_S, command.name)))
        except Exception as error:  # noqa: BLE001 - typed and raised below, after the others end
            failures[index] = _typed(error, command, step)
    try:
        _wait(step, started, report, timeout_s, progress_interval_s)
    except BaseException:
        if stop_devices is not None and not all(instance.done for _, instance in started):
            stop_devices()
        raise
    for command, instance in started:
        try:
            bounded(instance.get_responses, CALL_TIMEOUT_S, command.name)  # raises its SiLA error, if any
        except Exception as error:  # noqa: BLE001 - typed below
            failures[commands.index(command)] = _typed(error, command, step)
    if failures:
        first, *others = (failures[index] for index in sorted(failures))
        for other in others:
            logger.warning("%s: a further command failed as well: %s", step, other)
        raise first
    report.finished()


def _wait(
    step: str,
    started: Sequence[tuple[Command, Any]],
    report: _Reporter,
    timeout_s: float,
    progress_interval_s: float,
) -> None:
    deadline = time.monotonic() + timeout_s
    next_report = 0.0
    while not all(instance.done for _, instance in started):
        now = time.monotonic()
        if now > deadline:
            running = ", ".join(command.name for command, instance in started if not instance.done)
            raise StepTimeout(f"not finished after {timeout_s:.0f} s: {running}", command=step, step=step)
        if now >= next_report:
            next_report = now + progress_interval_s
            report.running([instance for _, instance in started])
        time.sleep(DONE_CHECK_S)


def _typed(error: Exception, command: Command, step: str) -> Exception:
    typed = translate(error, command=command.name, step=step)
    if typed is not error:
        typed.__cause__ = error
    return typed


class _Reporter:
    """Turns command instances into StepProgress records; progress never goes down."""

    def __init__(self, step: str, on_progress: ProgressCallback | None) -> None:
        self._step = step
        self._on_progress = on_progress
        self._highest = 0.0
        self._started = time.monotonic()

    def started(self) -> None:
        self._started = time.monotonic()
        self._emit(StepProgress(self._step, 0.0))

    def running(self, instances: Sequence[Any]) -> None:
        if not instances:
            return
        least = min(
            1.0 if instance.done else min(1.0, max(0.0, instance.progress or 0.0)) for instance in instances
        )
        self._highest = max(self._highest, least)
        remaining = [
            instance.estimated_remaining_time.total_seconds()
            for instance in instances
            if not instance.done and instance.estimated_remaining_time is not None
        ]
        self._emit(StepProgress(self._step, self._highest, max(remaining, default=None), self._elapsed()))

    def finished(self) -> None:
        self._emit(StepProgress(self._step, 1.0, 0.0, self._elapsed(), done=True))

    def _elapsed(self) -> float:
        return time.monotonic() - self._started

    def _emit(self, record: StepProgress) -> None:
        if self._on_progress is not None:
            self._on_progress(record)
