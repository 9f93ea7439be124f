"""Callbacks that run every so many seconds of simulated time, after a physics step.

Why in simulated time: a sensor and the software that reads it (the base laser and localisation
at a few Hz) must run at the same instants whatever the wall clock and the machine's load do, so a
run is reproducible from its seed. Lives on the sim thread: Simulation.step() calls ``tick``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any


@dataclass
class _Timer:
    period_s: float
    callback: Callable[[Any], None]
    due_s: float


class SimClock:
    """Timers on the simulation clock; a callback gets the Simulation."""

    def __init__(self) -> None:
        self._timers: list[_Timer] = []

    def every(self, period_s: float, callback: Callable[[Any], None], now_s: float = 0.0) -> None:
        """Call ``callback(sim)`` at the first step at or after every ``period_s`` from ``now_s``."""
        if period_s <= 0.0:
            raise ValueError(f"a timer's period must be positive, not {period_s} s")
        self._timers.append(_Timer(period_s, callback, now_s + period_s))

    def tick(self, sim: Any) -> None:
        for timer in self._timers:
            if sim.sim_time >= timer.due_s - 1e-9:
                # the next one a period after this one, never in the past (a long step skips beats)
                timer.due_s = max(timer.due_s + timer.period_s, sim.sim_time + 0.5 * timer.period_s)
                timer.callback(sim)
