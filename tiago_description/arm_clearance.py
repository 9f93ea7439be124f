"""How near an arm, its gripper and the plate it holds come to boxes standing in the lab (m).

Why: a station's marker stands on a board beside its row of nests, and an arm on its way to the end
nest may sweep through it (seen: a finger and the wrist touched the board on a joint-space move to a
nest's approach, a held plate met it on a straight one). The skills check a planned path against what
they know stands there before anything moves, as a real robot's motion planner would, from the robot
model's own collision shapes (the URDF the simulator loads too) and nothing of the simulator.

Pure computation (pinocchio with coal); one instance per thread, like `RobotKinematics`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from tiago_description import robot_model
from tiago_description.kinematics import RobotKinematics

try:  # pinocchio 3 and 4 ship coal; hpp-fcl is its former name
    import coal as _fcl
except ImportError:  # pragma: no cover - older wheels
    import hppfcl as _fcl

JOINT_STEP_RAD = 0.02
"""A joint-space path is checked at configurations this far apart on the joint that moves most (about
a centimetre at the fingers, the links' radius a fifth of it)."""


@dataclass(frozen=True)
class Box:
    """A box standing in the lab: its name for messages, its full size (m) and its centre's pose in
    base_footprint."""

    name: str
    size: tuple[float, float, float]
    T_base_box: np.ndarray


@dataclass(frozen=True)
class HeldBox:
    """What the gripper holds, as a box: its full size (m) and its centre's pose in the grasping frame."""

    size: tuple[float, float, float]
    T_grasp_box: np.ndarray


@dataclass(frozen=True)
class Clearance:
    """The least distance (m) between the arm's side (links, gripper, held box) and the boxes, and which
    pair it was; at `index` of the configurations given. Negative: they overlap by that much."""

    distance_m: float
    link: str = ""
    obstacle: str = ""
    index: int = -1

    def describe(self) -> str:
        if not self.link:
            return "nothing to pass"
        return f"{self.link} {self.distance_m * 1000:.0f} mm from {self.obstacle}"


BODY_LINKS_SKIPPED = ("1", "2")
"""The arm's shoulder links (1, 2) sit on the torso by design; from link 3 on, the arm and its gripper are
checked against the rest of the robot (torso, head, base, hotel, the other arm), 10 cm or more apart
in "Benchtop"."""


class ArmClearance:
    """Distances from one arm's collision shapes to boxes (and, asked, to the rest of the robot), over
    a path of joint configurations."""

    def __init__(self, kinematics: RobotKinematics) -> None:
        self.kinematics = kinematics
        self._geometry = pin.buildGeomFromUrdf(
            kinematics.model, str(robot_model.urdf_path()), pin.GeometryType.COLLISION
        )

    def nearest(
        self,
        arm: str,
        start: Mapping[str, float],
        path: Iterable[Mapping[str, float]],
        boxes: Sequence[Box],
        held: HeldBox | None = None,
        body: bool = False,
    ) -> Clearance:
        """The least clearance over `path` (joint positions per configuration, each over `start`, the
        full readings), between `arm`'s links, gripper and `held` and `boxes` (and with `body`, the
        rest of the robot)."""
        scene = self.scene(arm, boxes, held, body)
        best = Clearance(math.inf)
        base = dict(start)
        for index, configuration in enumerate(path):
            nearest = scene.nearest(self.kinematics.configuration({**base, **configuration}))
            if nearest.distance_m < best.distance_m:
                best = dataclasses.replace(nearest, index=index)
        return best

    def scene(self, arm: str, boxes: Sequence[Box], held: HeldBox | None = None, body: bool = False) -> Scene:
        """The collision pairs to check for `arm` (its links, gripper and `held` against `boxes`, and
        with `body` against the rest of the robot), to ask for many configurations."""
        model = self.kinematics.model
        geometry = pin.GeometryModel()
        arm_prefixes = (f"arm_{arm}_", f"gripper_{arm}_")
        moving, robot = [], []
        for obj in self._geometry.geometryObjects:
            index = geometry.addGeometryObject(obj)
            if obj.name.startswith(arm_prefixes):
                if not obj.name.startswith(tuple(f"arm_{arm}_{n}_" for n in BODY_LINKS_SKIPPED)):
                    moving.append(index)
                elif not body:
                    moving.append(index)
            else:
                robot.append(index)
        if held is not None:
            frame = model.frames[model.getFrameId(f"gripper_{arm}_grasping_frame")]
            placement = frame.placement * pin.SE3(np.asarray(held.T_grasp_box, dtype=float))
            plate = pin.GeometryObject("held plate", frame.parentJoint, placement, _fcl.Box(*held.size))
            moving.append(geometry.addGeometryObject(plate))
        fixed = [
            geometry.addGeometryObject(
                pin.GeometryObject(
                    box.name, 0, pin.SE3(np.asarray(box.T_base_box, dtype=float)), _fcl.Box(*box.size)
                )
            )
            for box in boxes
        ]
        for a in moving:
            for b in fixed + (robot if body else []):
                geometry.addCollisionPair(pin.CollisionPair(a, b))
        return Scene(model, geometry)


class Scene:
    """Collision pairs of one arm against what it must not touch, asked per configuration (pinocchio q)."""

    def __init__(self, model: pin.Model, geometry: pin.GeometryModel) -> None:
        self.model = model
        self.geometry = geometry
        self._data = model.createData()
        self._geometry_data = pin.GeometryData(geometry)

    def nearest(self, q: np.ndarray) -> Clearance:
        if len(self.geometry.collisionPairs) == 0:
            return Clearance(math.inf)
        pin.computeDistances(self.model, self._data, self.geometry, self._geometry_data, q)
        distances = [result.min_distance for result in self._geometry_data.distanceResults]
        at = int(np.argmin(distances))
        pair = self.geometry.collisionPairs[at]
        names = self.geometry.geometryObjects
        return Clearance(float(distances[at]), names[pair.first].name, names[pair.second].name)


def joint_path(start: Mapping[str, float], goal: Mapping[str, float]) -> list[dict[str, float]]:
    """The configurations a one-segment joint move from `start` to `goal` passes (the controllers move
    every joint on one speed profile, so the path is the straight line in joint space), JOINT_STEP_RAD
    apart on the joint that moves most; `goal` last."""
    largest = max((abs(goal[name] - start.get(name, 0.0)) for name in goal), default=0.0)
    count = max(1, math.ceil(largest / JOINT_STEP_RAD))
    return [
        {
            name: start.get(name, 0.0) + (value - start.get(name, 0.0)) * i / count
            for name, value in goal.items()
        }
        for i in range(1, count + 1)
    ]
