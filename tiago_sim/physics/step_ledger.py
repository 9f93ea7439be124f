"""Physics steps and the CPU they took, by step length and solver iterations.

Why: the physics step is most of the sim thread's CPU; which regime eats it tells where a faster
simulation has to come from (the sim thread logs the summary when it stops). Lives on the sim
thread.
"""

from __future__ import annotations


class StepLedger:
    """Physics steps and the CPU they took, by step length and solver iterations.

    Why: the physics step is most of the sim thread's CPU; which regime eats it tells where a
    faster simulation has to come from (logged when the sim thread stops)."""

    def __init__(self) -> None:
        self.entries: dict[tuple[float, int], list[float]] = {}  # -> [steps, sim s, CPU s]

    def record(self, step_s: float, iterations: int, cpu_s: float) -> None:
        entry = self.entries.setdefault((step_s, iterations), [0, 0.0, 0.0])
        entry[0] += 1
        entry[1] += step_s
        entry[2] += cpu_s

    def summary(self) -> str:
        rows = sorted(self.entries.items(), key=lambda item: -item[1][2])
        return "; ".join(
            f"1/{round(1 / step_s)} s x {iterations} iterations: {int(steps)} steps, "
            f"{sim_s:.1f} s simulated, {cpu_s:.2f} s CPU ({cpu_s / steps * 1000:.2f} ms/step)"
            for (step_s, iterations), (steps, sim_s, cpu_s) in rows
        )
