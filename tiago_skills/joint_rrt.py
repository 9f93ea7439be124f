"""A joint-space way around what the arm must not touch: RRT-Connect, then shortcuts.

Why: beside a station's marker board, at the edge of the arm's reach, neither a straight tool line nor
a single joint-space move nor a way via the bench's front was clear (random layout 132040: the palm
crossed the board near the nest on every direct move, the lines ran into joint limits). Two trees,
one grown from the start and one from the target's IK solutions, are grown toward random
configurations and toward each other until they meet (Kuffner and LaValle's RRT-Connect); the path
is then shortened by joining waypoints that see each other. Every configuration on the way, at
`resolution` apart, passes the caller's check (`is_free`), which holds the robot model's collision
shapes, so the way is as safe as the model. Pure computation; the caller's generator makes it
repeatable.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

STEP_RAD = 0.3
"""The longest edge a tree grows at once (Euclidean, over all joints)."""
RESOLUTION_RAD = 0.02
"""Configurations on an edge are checked this far apart on the joint that moves most."""
MAX_SAMPLES = 1500
GOAL_BIAS = 0.1
SHORTCUT_TRIES = 80


@dataclass
class _Tree:
    points: list[np.ndarray] = field(default_factory=list)
    parents: list[int] = field(default_factory=list)

    def add(self, q: np.ndarray, parent: int) -> int:
        self.points.append(q)
        self.parents.append(parent)
        return len(self.points) - 1

    def nearest(self, q: np.ndarray) -> int:
        return int(np.argmin(np.linalg.norm(np.asarray(self.points) - q, axis=1)))

    def branch(self, index: int) -> list[np.ndarray]:
        """The points from the root to `index`."""
        out = []
        while index >= 0:
            out.append(self.points[index])
            index = self.parents[index]
        return out[::-1]


def segment_free(is_free: Callable[[np.ndarray], bool], a: np.ndarray, b: np.ndarray) -> bool:
    """Whether every configuration between a and b (not a itself) passes, RESOLUTION_RAD apart."""
    count = max(1, math.ceil(float(np.max(np.abs(b - a))) / RESOLUTION_RAD))
    return all(is_free(a + (b - a) * i / count) for i in range(1, count + 1))


def plan_around(
    is_free: Callable[[np.ndarray], bool],
    start: np.ndarray,
    goals: Sequence[np.ndarray],
    lower: np.ndarray,
    upper: np.ndarray,
    rng: np.random.Generator,
    max_samples: int = MAX_SAMPLES,
) -> list[np.ndarray] | None:
    """Waypoints from `start` to one of `goals` (start and goal included) whose straight joint-space
    segments are free, or None when none was found within `max_samples`."""
    goals = [g for g in goals if is_free(g)]
    if not goals:
        return None
    trees = (_Tree(), _Tree())
    trees[0].add(np.asarray(start, dtype=float), -1)
    for goal in goals:
        trees[1].add(np.asarray(goal, dtype=float), -1)
    grow, other = trees
    for _ in range(max_samples):
        target = goals[rng.integers(len(goals))] if rng.random() < GOAL_BIAS else rng.uniform(lower, upper)
        new = _extend(is_free, grow, target)
        if new is not None:
            met = _connect(is_free, other, grow.points[new])
            if met is not None:
                path = _join(trees, grow, new, met)
                return _shortcut(is_free, path, rng)
        grow, other = other, grow
    return None


def _extend(is_free: Callable[[np.ndarray], bool], tree: _Tree, target: np.ndarray) -> int | None:
    near = tree.nearest(target)
    offset = target - tree.points[near]
    length = float(np.linalg.norm(offset))
    q = target if length <= STEP_RAD else tree.points[near] + offset * (STEP_RAD / length)
    if not segment_free(is_free, tree.points[near], q):
        return None
    return tree.add(q, near)


def _connect(is_free: Callable[[np.ndarray], bool], tree: _Tree, target: np.ndarray) -> int | None:
    """Grow `tree` straight toward `target` until it reaches it (its index) or is blocked (None)."""
    while True:
        new = _extend(is_free, tree, target)
        if new is None:
            return None
        if np.allclose(tree.points[new], target):
            return new


def _join(trees: tuple[_Tree, _Tree], grow: _Tree, new: int, met: int) -> list[np.ndarray]:
    start_side, goal_side = (new, met) if grow is trees[0] else (met, new)
    return trees[0].branch(start_side) + trees[1].branch(goal_side)[::-1][1:]


def _shortcut(
    is_free: Callable[[np.ndarray], bool], path: list[np.ndarray], rng: np.random.Generator
) -> list[np.ndarray]:
    for _ in range(SHORTCUT_TRIES):
        if len(path) <= 2:
            break
        i, j = sorted(rng.choice(len(path), size=2, replace=False))
        if j - i > 1 and segment_free(is_free, path[i], path[j]):
            path = path[: i + 1] + path[j:]
    return path
