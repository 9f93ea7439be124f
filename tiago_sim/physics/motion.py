"""Motion: one running activity of the simulated robot, advanced by Simulation.step().

Why a status object rather than a blocking call: the sim thread must keep stepping physics while
callers (ROS action servers) watch progress and may cancel, in the spirit of Ophyd's Status.
Lives on the sim thread; other threads read its fields only through the sim thread's jobs.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Sequence

log = logging.getLogger(__name__)

CANCELED = "CANCELED"
BUSY = "BUSY"


class Motion:
    """Base class: subclasses implement ``tick(dt)`` and call ``finish``."""

    def __init__(self, name: str, resources: frozenset[str] = frozenset()) -> None:
        self.name = name
        self.resources = resources
        self.phase = "starting"
        self.progress = 0.0
        self.remaining_s = 0.0
        self.done = False
        self.success = False
        self.error_code = ""
        self.message = ""
        self.cancel_requested = False
        self.elapsed_s = 0.0
        # Set by finish(): a waiting action thread wakes at once instead of at its next poll (every
        # poll lost up to 20 ms of wall time during which the idle robot's clock ran on at 1x).
        self.finished = threading.Event()

    def cancel(self) -> None:
        """Ask to stop safely; the motion ends (CANCELED) on one of the next steps."""
        self.cancel_requested = True

    def finish(self, success: bool, error_code: str = "", message: str = "") -> None:
        if self.done:
            return
        self.done = True
        self.success = success
        self.error_code = "" if success else (error_code or "MOTION_FAILED")
        self.message = message or ("done" if success else error_code)
        self.progress = 1.0 if success else self.progress
        self.remaining_s = 0.0
        self.finished.set()
        level = logging.DEBUG if success else logging.INFO
        log.log(level, "%s finished: success=%s %s %s", self.name, success, self.error_code, self.message)

    def advance(self, dt: float) -> None:
        """Called once per physics step before stepping."""
        if self.done:
            return
        self.elapsed_s += dt
        self.tick(dt)

    def tick(self, dt: float) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def __repr__(self) -> str:
        state = "done" if self.done else "running"
        return (
            f"<Motion {self.name} {state} phase={self.phase} progress={self.progress:.2f} {self.error_code}>"
        )


class FailedMotion(Motion):
    """A motion that could not start (bad goal, busy, unreachable); done from the start."""

    def __init__(self, name: str, error_code: str, message: str) -> None:
        super().__init__(name)
        self.finish(False, error_code, message)

    def tick(self, dt: float) -> None:
        return


class CompletedMotion(Motion):
    """Nothing to do (e.g. dock while docked): done and successful from the start."""

    def __init__(self, name: str, message: str) -> None:
        super().__init__(name)
        self.finish(True, message=message)

    def tick(self, dt: float) -> None:
        return


class SequenceMotion(Motion):
    """Runs motions made by ``stages`` one after another; each stage is (phase, factory, weight,
    estimated seconds). The remaining time is the running stage's own estimate plus the estimates
    of the stages after it.

    A factory is called when its stage starts, so it can use the state the previous stage left.
    """

    def __init__(
        self,
        name: str,
        stages: Sequence[tuple[str, Callable[[], Motion], float, float]],
        resources: frozenset[str] = frozenset(),
    ) -> None:
        super().__init__(name, resources)
        self.stages = list(stages)
        self.remaining_s = sum(estimate for *_, estimate in self.stages)
        self.index = -1
        self.current: Motion | None = None
        self.total_weight = sum(weight for _, _, weight, _ in self.stages) or 1.0
        self.weight_done = 0.0

    def cancel(self) -> None:
        super().cancel()
        if self.current is not None:
            self.current.cancel()

    def tick(self, dt: float) -> None:
        if self.current is None or self.current.done:
            if self.current is not None:
                if not self.current.success:
                    self.finish(False, self.current.error_code, f"{self.phase}: {self.current.message}")
                    return
                self.weight_done += self.stages[self.index][2]
            if self.cancel_requested:
                self.finish(False, CANCELED, "canceled")
                return
            self.index += 1
            if self.index >= len(self.stages):
                self.finish(True)
                return
            self.phase, factory, _, _ = self.stages[self.index]
            self.current = factory()
            if self.current.done:  # failed at once
                self.tick(0.0)
                return
        self.current.advance(dt)
        weight = self.stages[self.index][2]
        self.progress = min(1.0, (self.weight_done + weight * self.current.progress) / self.total_weight)
        later_s = sum(estimate for *_, estimate in self.stages[self.index + 1 :])
        self.remaining_s = self.current.remaining_s + later_s
