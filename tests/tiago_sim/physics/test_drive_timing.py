"""A drive's remaining-time estimate against what the drive then takes, in simulated time.

Why: the estimate is what navigation's feedback (and through it a SiLA command's remaining time)
says, so it must follow the drive as DriveMotion makes it, phase by phase. Real PyBullet, the
default lab, the planner's paths between its stations.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from lab_description.world import load_world
from tiago_description.drive_timing import profile_s, rest_to_rest_s
from tiago_sim.navigation.occupancy_map import build_map
from tiago_sim.navigation.planner import GlobalPlanner
from tiago_sim.physics.simulation import Simulation


@pytest.fixture(scope="module")
def lab() -> Iterator[tuple[Simulation, GlobalPlanner]]:
    world = load_world()
    sim = Simulation(world, seed=3)
    assert sim.run(sim.undock()).success
    yield sim, GlobalPlanner(build_map(world))
    sim.close()


@pytest.mark.parametrize("poi", ["station_a_work", "station_b_work"])
def test_a_drives_estimate_foretells_its_end_within_5_percent(
    lab: tuple[Simulation, GlobalPlanner], poi: str
) -> None:
    sim, planner = lab
    goal = sim.world.pois[poi]
    motion = sim.follow_path(planner.plan(sim.pose_estimate(), (goal.x, goal.y, goal.yaw)), goal.yaw)
    began, samples = sim.sim_time, []
    while not motion.done:
        samples.append((sim.sim_time - began, motion.remaining_s))
        sim.step()
    assert motion.success, motion.message
    took = sim.sim_time - began
    for quarter in (0.0, 0.25, 0.5, 0.75):
        at, estimate = min(samples, key=lambda sample: abs(sample[0] - quarter * took))
        assert estimate == pytest.approx(took - at, abs=0.05 * took), (quarter, took)


def test_the_profile_from_rest_to_rest_and_from_speed() -> None:
    assert rest_to_rest_s(3.0, 0.5, 1.0) == pytest.approx(5.0)  # 2 s up, 1 s cruise, 2 s down
    assert profile_s(3.0, 0.5, 0.5, 1.0, start_speed=1.0) == pytest.approx(4.0)  # no speeding up
    assert profile_s(1.0, 1.0, 1.0, 1.0, stop_short=0.5) == pytest.approx(1.0)  # up to 1 m/s, handed on
