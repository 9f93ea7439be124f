"""RRT-Connect finds a joint-space way through a gap, every segment free, and says so when there is none.

Why: the skills' last way to a nest beside a marker board (tiago_skills.bench_route, "around") is
searched in joint space; here the search is checked on a plane with a wall, where the answer is known.
"""

from __future__ import annotations

import numpy as np

from tiago_skills.joint_rrt import RESOLUTION_RAD, plan_around, segment_free

LOWER, UPPER = np.array([-1.0, -1.0]), np.array([1.0, 1.0])


def wall_with_gap(gap: float):  # noqa: ANN201
    """A wall along x = 0, 0.1 thick, open only where |y - 0.7| < gap / 2."""

    def is_free(q: np.ndarray) -> bool:
        return abs(q[0]) > 0.05 or abs(q[1] - 0.7) < gap / 2

    return is_free


def test_the_way_passes_the_gap_and_every_step_of_it_is_free() -> None:
    is_free = wall_with_gap(0.1)
    start, goal = np.array([-0.8, -0.5]), np.array([0.8, -0.5])
    path = plan_around(is_free, start, [goal], LOWER, UPPER, np.random.default_rng(1))
    assert path is not None
    assert np.allclose(path[0], start) and np.allclose(path[-1], goal)
    assert all(segment_free(is_free, a, b) for a, b in zip(path, path[1:], strict=False))
    crossing = [q for a, b in zip(path, path[1:], strict=False) for q in (a, b) if abs(q[0]) <= 0.05]
    assert all(abs(q[1] - 0.7) < 0.05 for q in crossing)
    dense = [a + (b - a) * t for a, b in zip(path, path[1:], strict=False) for t in np.linspace(0, 1, 50)]
    assert any(abs(q[0]) < RESOLUTION_RAD for q in dense), "the way never crossed the wall's line"


def test_a_closed_wall_gives_no_way_and_a_blocked_goal_is_dropped() -> None:
    closed = wall_with_gap(0.0)
    start, goal = np.array([-0.8, -0.5]), np.array([0.8, -0.5])
    assert plan_around(closed, start, [goal], LOWER, UPPER, np.random.default_rng(1), max_samples=300) is None
    open_wall = wall_with_gap(0.2)
    inside = np.array([0.0, -0.5])  # in the wall
    path = plan_around(open_wall, start, [inside, goal], LOWER, UPPER, np.random.default_rng(2))
    assert path is not None and np.allclose(path[-1], goal)
