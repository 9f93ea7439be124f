"""Step a Simulation by hand: through one motion (keeping every physics step's length) or for a
span of simulated time.

Why: the adaptive step is checked from several tests (free motion long, plate handling short), and
steps vary from 1/240 to 1/60 s, so tests count simulated time, never steps; one helper serves all.
"""

from __future__ import annotations

from tiago_sim.physics.simulation import Simulation


def step_lengths(sim: Simulation, motion, limit_s: float = 120.0) -> list[float]:
    """Step until ``motion`` is done; the step lengths in s, in order."""
    lengths = []
    while not motion.done:
        sim.step()
        lengths.append(sim.last_step_s)
        assert sim.sim_time < limit_s, f"{motion} still running at {sim.sim_time:.1f} s"
    return lengths


def step_for(sim: Simulation, seconds: float) -> None:
    """Step ``seconds`` of simulated time on, whatever length the steps take (1/240 to 1/60 s)."""
    until = sim.sim_time + seconds
    while sim.sim_time < until:
        sim.step()
