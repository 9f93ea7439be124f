"""A fraction done that never goes down: the one place that rule is written.

Why in the model: every layer that reports progress needs it (the sim node's action feedback, the
sequencer's task feedback, the bridge's goals and commands). A robot side that re-plans may
estimate less than before; whoever shows the number (a SiLA client's progress bar, Bluesky's
ProgressBar) must never see it shrink. Thread-safe (one lock). Standard library only.
"""

from __future__ import annotations

import math
import threading


class MonotonicProgress:
    """A fraction done in 0..1 that only rises: the one place the rule is written."""

    def __init__(self, fraction: float = 0.0) -> None:
        self._lock = threading.Lock()
        self._fraction = 0.0
        self.advance(fraction)

    @property
    def fraction(self) -> float:
        with self._lock:
            return self._fraction

    def advance(self, estimate: float) -> float:
        """Take a new estimate; return the fraction to show: clamped to 0..1 and never below the
        highest shown so far. A NaN or infinite estimate changes nothing."""
        with self._lock:
            if math.isfinite(estimate):
                self._fraction = max(self._fraction, min(1.0, max(0.0, estimate)))
            return self._fraction
