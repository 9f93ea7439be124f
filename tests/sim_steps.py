"""Step a Simulation through one motion and keep the length of every physics step it took.

Why: the adaptive step is checked from several tests (free motion long, plate handling short);
one helper steps them all alike.
"""

from __future__ import annotations

from tiago_sim.simulation import Simulation


def step_lengths(sim: Simulation, motion, limit_s: float = 120.0) -> list[float]:
    """Step until ``motion`` is done; the step lengths in s, in order."""
    lengths = []
    while not motion.done:
        sim.step()
        lengths.append(sim.last_step_s)
        assert sim.sim_time < limit_s, f"{motion} still running at {sim.sim_time:.1f} s"
    return lengths
