"""Looks into a nest with the head camera's depth image: is a plate there, and where does it lie.

Why apart from the marker motion: the motion moves the tool to where the marker shows the nest; these
looks read the nest itself, for the check of a lab without nest sensors (`inspect`,
perception.nest_occupancy) and for the plate a pick then grasps (`find_plate`, pick_correction).
What they saw is kept while the base stands where it saw it (odometry), so that the nest's motions
use it. Only the head camera's depth image, the joint readings taken with it and the kinematic model
are used, as on the real robot. Lives on: the marker motion's executor thread (one goal at a time).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np
from labware_interfaces.msg import ErrorCodes

from lab_description.world import World
from tiago_description import transforms as tf
from tiago_description.kinematics import CAMERA_FRAME, RobotKinematics, head_aim
from tiago_skills.base_alignment import HEAD_JOINTS
from tiago_skills.goal_run import ActionAbort, GoalRun
from tiago_skills.joint_commands import move_joints
from tiago_skills.marker_sighting import MarkerSighting, pose_msg, same_place
from tiago_skills.perception.nest_occupancy import NestView, view_nest
from tiago_skills.perception.site_frames import nest_in_base
from tiago_skills.pick_correction import LOOK_AT_NEST, plate_in_nest

log = logging.getLogger(__name__)
T = TypeVar("T")

Odometry = tuple[float, float, float]


class NestLooks:
    """The looks into a station's nests, and what the last of them saw, per nest."""

    def __init__(self, world: World, kinematics: RobotKinematics, lock: threading.Lock) -> None:
        self.world = world
        self.kinematics = kinematics
        self._lock = lock  # the kinematics' data is shared with the marker motion
        # (station, nest) -> (odometry, height) of the floor the last look saw empty in that nest
        self.floors_seen: dict[tuple[str, int], tuple[Odometry, float]] = {}
        # (station, nest) -> (odometry, pose in the nest frame) of the plate the last look found there
        self.plates_seen: dict[tuple[str, int], tuple[Odometry, tf.Planar]] = {}

    @staticmethod
    def nest_seen(
        station: Any, sub_position: int, sighting: MarkerSighting, above_m: float = 0.0
    ) -> np.ndarray:
        """The nest (or the point ``above_m`` over it) in base_footprint, from a marker sighting."""
        T_marker_site = station.T_marker_site(sub_position) @ tf.make_transform((0.0, 0.0, above_m))
        height = float((station.T_world_marker() @ T_marker_site)[2, 3])
        return nest_in_base(sighting.T_base_marker, station.T_table_marker(), T_marker_site, height)

    def inspect(self, run: GoalRun, station: Any, sub_position: int, sighting: MarkerSighting) -> dict:
        """Whether a plate lies in the nest, from the depth image: from the head as it stands if the
        nest is in view, else aimed at it and turned back after, so that a later place measures its
        held plate with the head where it saw the marker (place_correction); NEST_NOT_SEEN when the
        camera cannot see into the nest."""
        T_base_site = self.nest_seen(station, sub_position, sighting)
        key, odometry = (station.name, sub_position), run.read(lambda hardware: tuple(hardware.odometry()))
        floor = self.floors_seen.get(key)
        floor_m = floor[1] if floor is not None and same_place(floor[0], odometry) else None
        view = self._view(run, T_base_site, floor_m)
        if not view.seen:
            where = f"nest {sub_position} of {station.name}"
            log.info("%s not seen from here (%s): aiming the head at it", where, view.reason)
            view = self._aimed_at(run, T_base_site, lambda: self._view(run, T_base_site, floor_m))
        log.info("nest %d of %s: %s", sub_position, station.name, view.reason)
        if view.occupied is False:
            self.floors_seen[key] = (odometry, view.height_m)
        if not view.seen:
            raise ActionAbort(
                ErrorCodes.NEST_NOT_SEEN,
                f"the head camera cannot see into nest {sub_position} of {station.name}: {view.reason}",
            )
        return {
            "marker_in_base": pose_msg(sighting.T_base_marker),
            "nest_occupied": bool(view.occupied),
            "plate_seated": view.seated,
        }

    def find_plate(self, run: GoalRun, station: Any, sub_position: int, sighting: MarkerSighting) -> str:
        """Where the plate lies in the nest before a pick (pick_correction), kept for the nest's motions
        while the base stands here. A put's nest reads empty and keeps nothing."""
        key = (station.name, sub_position)
        self.plates_seen.pop(key, None)
        T_base_site = self.nest_seen(station, sub_position, sighting)

        def plate_seen() -> tuple[tf.Planar | None, str]:
            return plate_in_nest(*self._nest_image(run, T_base_site), self.world.labware_types.values())

        pose, why = plate_seen()
        if pose is None and why in LOOK_AT_NEST:
            log.info("nest %d of %s: %s; aiming the head at it", sub_position, station.name, why)
            pose, why = self._aimed_at(run, T_base_site, plate_seen)
        log.info("nest %d of %s: %s", sub_position, station.name, f"plate at {why}" if pose else why)
        if pose is not None:
            self.plates_seen[key] = (sighting.odometry, pose)
        return why

    def _view(self, run: GoalRun, T_base_site: np.ndarray, floor_m: float | None) -> NestView:
        depth, intrinsics, T_site_optical = self._nest_image(run, T_base_site)
        sizes = [(t.length, t.width, t.height) for t in self.world.labware_types.values()]
        return view_nest(depth, intrinsics, T_site_optical, sizes, floor_m)

    def _nest_image(self, run: GoalRun, T_base_site: np.ndarray) -> tuple[np.ndarray, Any, np.ndarray]:
        """A depth image, its intrinsics and the camera's pose in the nest frame when it was taken."""
        run.feedback(max(run.progress, 0.1), "looking into the nest", 0.0, force=True)
        frame = run.read(lambda hardware: hardware.capture_head_camera())
        with self._lock:
            T_base_optical = self.kinematics.forward(frame.joints, CAMERA_FRAME)
        return frame.depth, frame.intrinsics, tf.invert(T_base_site) @ T_base_optical

    def _aimed_at(self, run: GoalRun, T_base_site: np.ndarray, look: Callable[[], T]) -> T:
        """``look()`` with the head aimed at the nest, then turned back: a later place measures its held
        plate with the head where it saw the marker (place_correction)."""
        joints = run.read(lambda hardware: dict(hardware.joint_positions()))
        back = {name: joints[name] for name in HEAD_JOINTS}
        aim = head_aim(self.kinematics, joints, T_base_site[:3, 3])
        low = max(run.progress, 0.2)
        run.follow(move_joints(aim), span=(low, low + (1.0 - low) / 3))
        seen = look()
        run.follow(move_joints(back), span=(low + 2 * (1.0 - low) / 3, 1.0))
        return seen
