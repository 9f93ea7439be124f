"""A bench top with nests, drawn in PyBullet boxes and seen by a head camera: the scene the nest
perception tests render (a real renderer, depth noise added as the disturbance campaigns draw it)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import pybullet as p

from tiago_description import transforms as tf
from tiago_sim.physics.camera import CameraIntrinsics, optical_frame_looking_at, render_rgbd

RIM = 0.006  # a nest's rim about its pocket (m)


def box(client: int, size: Sequence[float], T_world_centre: np.ndarray) -> None:
    half = [s / 2 for s in size]
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    position, quat = tf.to_pose(T_world_centre)
    p.createMultiBody(0, shape, visual, position, quat, physicsClientId=client)


def nest_rims(client: int, T_world_nest: np.ndarray) -> None:
    """The four rims about a plate's pocket, 1 to 2 mm clear of an SBS plate."""
    for side in (-1, 1):
        box(client, (0.15, 0.004, RIM), T_world_nest @ tf.make_transform((0, side * 0.046, RIM / 2)))
        box(client, (0.004, 0.1, RIM), T_world_nest @ tf.make_transform((side * 0.067, 0, RIM / 2)))


def rendered_depth(
    draw: Callable[[int], None], eye: np.ndarray, target: np.ndarray, noise_m: float, seed: int
) -> tuple[np.ndarray, np.ndarray]:
    """The depth image (with Gaussian noise of ``noise_m`` a pixel) of the scene ``draw`` builds, seen
    from ``eye`` towards ``target``, and T_world_optical."""
    client = p.connect(p.DIRECT)
    try:
        draw(client)
        T_world_optical = optical_frame_looking_at(eye, target)
        _rgb, depth = render_rgbd(client, T_world_optical, CameraIntrinsics())
        return depth + np.random.default_rng(seed).normal(0.0, noise_m, depth.shape), T_world_optical
    finally:
        p.disconnect(client)
