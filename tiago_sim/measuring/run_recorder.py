"""Pictures of one run, written by the sim node: overview frames and head-camera frames.

Why in the sim process: only it owns PyBullet, so it renders a fixed overview camera every few
simulated seconds and keeps every head-camera image the robot's perception used, marked by the
`annotate` function it is given (the start-up outlines the station marker with the detector the
robot runs, on the same pixels; the simulator itself knows no detector).
Frames go to ``<dir>/overview_NNNN.png`` and ``<dir>/head_NNNN.png``; the bench report turns
them into a strip and a GIF. Lives on the sim thread (it wraps the Simulation's methods).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from lab_description.world import World
from tiago_sim.physics.camera import CameraIntrinsics, optical_frame_looking_at, render_rgbd

log = logging.getLogger(__name__)

OVERVIEW_PERIOD_S = 4.0
OVERVIEW_INTRINSICS = replace(
    CameraIntrinsics(), width=480, height=360, fx=330.0, fy=330.0, cx=239.5, cy=179.5, far=20.0
)


def overview_camera_pose(world: World) -> np.ndarray:
    """T_world_optical of a camera high in a corner, looking at the middle of dock and stations."""
    points = [(world.dock_pose.x, world.dock_pose.y)]
    points += [(s.table_pose.x, s.table_pose.y) for s in world.stations]
    centre = np.array([*np.mean(points, axis=0), 0.4])
    spread = max(float(np.ptp([x for x, _ in points])), float(np.ptp([y for _, y in points])), 2.0)
    eye = centre + np.array([-0.55 * spread, -0.95 * spread, 1.1 * spread])
    return optical_frame_looking_at(eye, centre)


class RunRecorder:
    """Wraps a Simulation's `step` and `render_head_camera` to save frames to a directory."""

    def __init__(
        self,
        sim: Any,
        world: World,
        directory: Path,
        annotate: Callable[[np.ndarray, np.ndarray, CameraIntrinsics], np.ndarray] | None = None,
    ) -> None:
        self.sim = sim
        self.world = world
        self.annotate = annotate  # a head frame (rgb, depth, intrinsics) to the picture saved
        self.directory = directory
        directory.mkdir(parents=True, exist_ok=True)
        self.T_world_overview = overview_camera_pose(world)
        self.overview_count = 0
        self.head_count = 0
        self._next_overview_s = 0.0
        self._step = sim.step
        self._render_head = sim.render_head_camera
        sim.step = self.step
        sim.render_head_camera = self.render_head_camera

    def step(self) -> None:
        self._step()
        if self.sim.sim_time >= self._next_overview_s:
            self._next_overview_s = self.sim.sim_time + OVERVIEW_PERIOD_S
            self.save_overview()

    def save_overview(self) -> Path:
        rgb, _ = render_rgbd(self.sim.client_id, self.T_world_overview, OVERVIEW_INTRINSICS, shadow=True)
        self.overview_count += 1
        label = f"t = {self.sim.sim_time:5.1f} s (simulated)"
        canvas = np.ascontiguousarray(rgb.copy())
        cv2.putText(canvas, label, (8, 20), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (20, 20, 20), 1, cv2.LINE_AA)
        return self._write(f"overview_{self.overview_count:04d}.png", canvas)

    def render_head_camera(self, *args: Any, **kwargs: Any) -> tuple[np.ndarray, np.ndarray, Any]:
        rgb, depth, intrinsics = self._render_head(*args, **kwargs)
        canvas = rgb if self.annotate is None else self.annotate(rgb, depth, intrinsics)
        self.head_count += 1
        self._write(f"head_{self.head_count:04d}.png", canvas)
        return rgb, depth, intrinsics

    def _write(self, name: str, rgb: np.ndarray) -> Path:
        path = self.directory / name
        if not cv2.imwrite(str(path), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)):
            log.warning("could not write %s", path)
        return path
