"""How fast the robot's clock runs against the wall clock, read from its state reports.

Why: the robot side estimates remaining times on its own clock (simulated time in simulation,
which runs as fast as the machine allows while the robot moves and at 1x while it idles; a real
robot's clock is the wall clock). A SiLA client counts wall seconds, so a remaining time is
divided by the pace before it is reported. The pace is measured over the last few state reports
(their stamps against the wall time they arrived at), so it follows a change of pace within a
window; until two reports span a measurable time it is 1. Where the robot's clock is told to run at
a set pace (`set_nominal`: a paced simulation), that pace is the factor unless the measurement falls
below `TOO_SLOW` of it: the robot's clock is capped at the set pace, so a faster reading is the
arrival jitter of a few state reports on a loaded machine (it moved a reported remaining time by
20 to 40 % at pace 1), and only a reading far below says the machine cannot keep the pace.

Threads: `observe` is called on the ROS thread (a state listener), `to_wall_s` on any thread;
one lock guards the samples.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable

from ros_bridge.workcell import RobotStatus

WINDOW_S = 2.0  # s of wall time the pace is measured over (/robot_state comes at 2 Hz or faster)
MIN_SPAN_S = 0.2  # s of wall time two reports must span before their pace counts
TOO_SLOW = 0.5  # a measured pace below this share of the set one is believed (the machine cannot keep up)


class RobotPace:
    """Robot seconds per wall second over the last `window_s` (see the module docstring)."""

    def __init__(self, window_s: float = WINDOW_S, wall_clock: Callable[[], float] = time.monotonic) -> None:
        self._window_s = window_s
        self._wall_clock = wall_clock
        self._lock = threading.Lock()
        self._samples: deque[tuple[float, float]] = deque()  # (wall s, robot stamp s)
        self._nominal: float | None = None

    def set_nominal(self, pace: float | None) -> None:
        """The pace the robot's clock is told to run at; None or 0: none (as fast as it can)."""
        with self._lock:
            self._nominal = pace if pace else None

    def observe(self, status: RobotStatus) -> None:
        now = self._wall_clock()
        with self._lock:
            if self._samples and status.stamp_s < self._samples[-1][1]:
                self._samples.clear()  # the robot's clock started anew (a restarted robot side)
            self._samples.append((now, status.stamp_s))
            while len(self._samples) > 2 and now - self._samples[0][0] > self._window_s:
                self._samples.popleft()

    @property
    def factor(self) -> float:
        """Robot seconds per wall second: the set pace unless the measurement is far below it, then the
        measurement; 1 until measured (and none set)."""
        with self._lock:
            nominal = self._nominal
            if len(self._samples) < 2:
                return nominal or 1.0
            (wall_0, robot_0), (wall_1, robot_1) = self._samples[0], self._samples[-1]
        if wall_1 - wall_0 < MIN_SPAN_S or robot_1 <= robot_0:
            return nominal or 1.0
        measured = (robot_1 - robot_0) / (wall_1 - wall_0)
        if nominal is not None and measured >= TOO_SLOW * nominal:
            return nominal
        return measured

    def to_wall_s(self, robot_s: float) -> float:
        """A duration on the robot's clock, in wall seconds at the current pace."""
        return robot_s / self.factor
