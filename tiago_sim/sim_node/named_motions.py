"""The robot's fixed motions as `/play_motion2` plays them: by key, timed from where the joints stand.

Why: on a TIAGo++, PAL's play_motion2 plays named motions (`/play_motion2`) to the controllers;
the simulator serves the skills' own library (motions.yaml) the same way, so that the robot's
tools and the ROS adapter can play them by name on the twin. The library is written once for
either arm (`{side}`); here each motion is keyed per arm in PAL's style (`travel_right`).

As pal-robotics/play_motion2 (README at c1418fba) plays a motion: rows of joint positions at
times from the start; the first row is reached by an approach whose time is the longer of the
row's own and the largest joint change at `APPROACH_VELOCITY_RADPS`, at least `APPROACH_MIN_S`;
the later rows keep their spacing. One difference, stated: a play_motion2 file gives every joint
of a motion in every row, while a keyframe of the library names only the joints it moves; a joint
not yet named keeps where it stood at the start (a static file cannot say that, so the library is
not exported as one). Each later row's spacing is the time the joints' velocity limits need from
the row before (robot_port.trajectory_timing's rule, from rest to rest). Plain data: no ROS here.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from robot_port.trajectory_timing import ProfiledPath
from tiago_description.motion_library import MotionLibrary
from tiago_description.robot_model import ARM_SIDES

APPROACH_VELOCITY_RADPS = 0.5
"""play_motion2's default `approach_velocity` (rad/s; m/s for the torso)."""
APPROACH_MIN_S = 0.5
"""play_motion2's default `approach_min_duration`."""


@dataclass(frozen=True)
class TimedRows:
    """A motion as its controllers get it: every joint in every row, each row at its time."""

    joints: tuple[str, ...]
    rows: tuple[tuple[float, ...], ...]
    times_s: tuple[float, ...]


@dataclass(frozen=True)
class NamedMotion:
    """One motion of the library, for one arm."""

    key: str
    frames: tuple[Mapping[str, float], ...]
    description: str

    @property
    def joints(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(joint for frame in self.frames for joint in frame))

    def timed_from(self, current: Mapping[str, float], velocity_limits: Mapping[str, float]) -> TimedRows:
        """The rows and their times when played from the joints at `current`."""
        joints = self.joints
        rows = []
        last = {joint: current[joint] for joint in joints}
        for frame in self.frames:
            last = {**last, **frame}
            rows.append(tuple(float(last[joint]) for joint in joints))
        change = max(abs(value - current[joint]) for joint, value in zip(joints, rows[0], strict=True))
        times = [max(change / APPROACH_VELOCITY_RADPS, APPROACH_MIN_S)]
        limits = np.array([velocity_limits[joint] for joint in joints])
        for before, after in zip(rows[:-1], rows[1:], strict=True):
            step = np.array(after) - np.array(before)
            spacing = (
                ProfiledPath([np.array(before), np.array(after)], limits).duration if step.any() else 0.0
            )
            times.append(times[-1] + max(spacing, 1e-3))
        return TimedRows(joints, tuple(rows), tuple(times))


def motion_key(name: str, side: str) -> str:
    """The key of a library motion played with one arm, in PAL's style (`home_right`)."""
    return f"{name.lower()}_{side}"


def named_motions(library: MotionLibrary) -> dict[str, NamedMotion]:
    """Every fixed motion of `library`, once per arm, by key."""
    return {
        motion_key(name, side): NamedMotion(
            motion_key(name, side),
            tuple(library.frames_for(name, side)),
            f"{name} with the {side} arm (tiago_description/motions.yaml)",
        )
        for name in library.keyframes
        for side in ARM_SIDES
    }
