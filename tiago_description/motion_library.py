"""Named keyframe motions of the robot (PlayMotion), read from motions.yaml.

Fixed motions ("Travel", "Benchtop") are joint-space keyframes written for the right arm; the left
arm is the mirror image of the right in our model, so the same joint values serve it (joint
names carry a "{side}" placeholder). The hotel motions ("NestApproach", "Nest") depend on the
slot and are derived from the hotel slot frame of the robot model by IK when played: the grasping
frame points down into the pocket, the fingers close across the plate's short side.
Pure data and math; safe on any thread.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from tiago_description.transforms import make_transform

DEFAULT_MOTIONS_FILE = Path(__file__).with_name("motions.yaml")
HOTEL_MOTIONS = ("NestApproach", "Nest")


class MotionLibraryError(ValueError):
    """motions.yaml is missing a field or holds a wrong value (the message names the file and field)."""


@dataclass(frozen=True)
class HotelGrasp:
    """Where the grasping frame goes relative to a hotel slot frame (pocket floor centre, z up)."""

    grasp_height_m: float  # grasping frame origin above the pocket floor when in "Nest"
    approach_height_m: float  # extra height above that for "NestApproach"
    carry_height_m: float = 0.15  # tool rises this far above "NestApproach" to travel to/from the hotel
    # Grasping frame above the floor where a held plate is let go of (a nest's or a pocket's): the
    # plate then hangs this much minus grasp_height_m above the floor and drops the rest. 0: as
    # grasp_height_m, i.e. lowered until it would touch.
    release_height_m: float = 0.0

    def T_slot_grasp(self, approach: bool, releasing: bool = False) -> np.ndarray:
        """Grasp pose in the slot frame: x (approach) down, y (closing) across the short side.

        ``releasing``: the pose where a held plate is let go of (``release_height_m``)."""
        rotation = np.column_stack([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
        floor_height = max(self.release_height_m, self.grasp_height_m) if releasing else self.grasp_height_m
        height = floor_height + (self.approach_height_m if approach else 0.0)
        return make_transform((0.0, 0.0, height), rotation)


@dataclass(frozen=True)
class MotionLibrary:
    default_arm: str
    keyframes: dict[str, list[dict[str, float]]]  # joint names with "{side}" placeholder
    hotel: HotelGrasp
    speed_scale: float

    def names(self) -> list[str]:
        return [*self.keyframes, *HOTEL_MOTIONS]

    def frames_for(self, name: str, arm: str) -> list[dict[str, float]]:
        """The keyframes of a fixed motion with joint names for `arm`."""
        return [
            {joint.format(side=arm): value for joint, value in frame.items()}
            for frame in self.keyframes[name]
        ]


def load_motions(path: Path = DEFAULT_MOTIONS_FILE) -> MotionLibrary:
    """Read and check motions.yaml."""
    try:
        document = yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as error:
        raise MotionLibraryError(f"{path}: cannot read: {error}") from error

    def need(mapping: dict, key: str, where: str):
        if not isinstance(mapping, dict) or key not in mapping:
            raise MotionLibraryError(f"{path}: {where}{key} is missing")
        return mapping[key]

    keyframes: dict[str, list[dict[str, float]]] = {}
    for name, frames in need(document, "motions", "").items():
        if not isinstance(frames, list) or not frames:
            raise MotionLibraryError(f"{path}: motions.{name} must be a non-empty list of keyframes")
        checked = []
        for index, frame in enumerate(frames):
            if not isinstance(frame, dict) or not frame:
                raise MotionLibraryError(f"{path}: motions.{name}[{index}] must map joint names to values")
            try:
                checked.append({str(joint): float(value) for joint, value in frame.items()})
            except (TypeError, ValueError) as error:
                raise MotionLibraryError(f"{path}: motions.{name}[{index}]: {error}") from error
        keyframes[str(name)] = checked
    hotel = need(document, "hotel", "")
    return MotionLibrary(
        default_arm=str(document.get("default_arm", "right")),
        keyframes=keyframes,
        hotel=HotelGrasp(
            grasp_height_m=float(need(hotel, "grasp_height_m", "hotel.")),
            approach_height_m=float(need(hotel, "approach_height_m", "hotel.")),
            carry_height_m=float(need(hotel, "carry_height_m", "hotel.")),
            release_height_m=float(hotel.get("release_height_m", 0.0)),
        ),
        speed_scale=float(document.get("speed_scale", 1.0)),
    )
