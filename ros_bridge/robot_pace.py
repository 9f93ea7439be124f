"""How fast the robot's clock runs against the wall clock, read from its state reports.

Why: the robot side estimates remaining times on its own clock (simulated time in simulation,
which runs as fast as the machine allows while the robot moves and at 1x while it idles; a real
robot's clock is the wall clock). A SiLA client counts wall seconds, so a remaining time is
divided by the pace before it is reported. The pace is measured over the last few state reports
(their stamps against the wall time they arrived at), so it follows a change of pace within a
window; until two reports span a measurable time it is 1. Where the robot's clock is told to run at
a set pace (`set_nominal`: a paced simulation), that pace is the factor as long as the measurement
agrees with it within `NOMINAL_TOLERANCE`: the arrival times of a few state reports jitter by tens
of milliseconds on a loaded machine, which moved a reported remaining time by 10 to 20 % at pace 1;
a measurement far off the set pace (a machine too slow for it) still wins.

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
NOMINAL_TOLERANCE = 0.25  # a measured pace within this fraction of the set one is taken as the set one


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
        """Robot seconds per wall second: the set pace while the measurement agrees with it, else the
        measurement; 1 until measured (and none set)."""
        with self._lock:
            nominal = self._nominal
            if len(self._samples) < 2:
                return nominal or 1.0
            (wall_0, robot_0), (wall_1, robot_1) = self._samples[0], self._samples[-1]
        if wall_1 - wall_0 < MIN_SPAN_S or robot_1 <= robot_0:
            return nominal or 1.0
        measured = (robot_1 - robot_0) / (wall_1 - wall_0)
        if nominal is not None and abs(measured - nominal) <= NOMINAL_TOLERANCE * nominal:
            return nominal
        return measured

    def to_wall_s(self, robot_s: float) -> float:
        """A duration on the robot's clock, in wall seconds at the current pace."""
        return robot_s / self.factor
