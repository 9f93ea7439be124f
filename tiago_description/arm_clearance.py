"""How near an arm, its gripper and the plate it holds come to boxes standing in the lab (m).

Why: a station's marker stands on a board beside its row of nests, and an arm on its way to the end
nest may sweep through it (seen: a finger and the wrist touched the board on a joint-space move to a
nest's approach, a held plate met it on a straight one). The skills check a planned path against what
they know stands there before anything moves, as a real robot's motion planner would, from the robot
model's own collision shapes (the URDF the simulator loads too) and nothing of the simulator.

Pure computation (pinocchio with coal); one instance per thread, like `RobotKinematics`.
"""

from __future__ import annotations

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


class ArmClearance:
    """Distances from one arm's collision shapes to boxes, over a path of joint configurations."""

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
    ) -> Clearance:
        """The least clearance over `path` (joint positions per configuration, each over `start`, the
        full readings), between `arm`'s links, gripper and `held` and `boxes`."""
        if not boxes:
            return Clearance(math.inf)
        model = self.kinematics.model
        geometry = pin.GeometryModel()
        moving = [
            geometry.addGeometryObject(obj)
            for obj in self._geometry.geometryObjects
            if obj.name.startswith((f"arm_{arm}_", f"gripper_{arm}_"))
        ]
        if held is not None:
            frame = model.frames[model.getFrameId(f"gripper_{arm}_grasping_frame")]
            placement = frame.placement * pin.SE3(np.asarray(held.T_grasp_box, dtype=float))
            shape = _fcl.Box(*held.size)
            moving.append(
                geometry.addGeometryObject(
                    pin.GeometryObject("held plate", frame.parentJoint, placement, shape)
                )
            )
        fixed = [
            geometry.addGeometryObject(
                pin.GeometryObject(
                    box.name, 0, pin.SE3(np.asarray(box.T_base_box, dtype=float)), _fcl.Box(*box.size)
                )
            )
            for box in boxes
        ]
        for a in moving:
            for b in fixed:
                geometry.addCollisionPair(pin.CollisionPair(a, b))
        data = pin.GeometryData(geometry)
        model_data = model.createData()
        best = Clearance(math.inf)
        base = dict(start)
        for index, configuration in enumerate(path):
            q = self.kinematics.configuration({**base, **configuration})
            pin.computeDistances(model, model_data, geometry, data, q)
            for pair, result in zip(geometry.collisionPairs, data.distanceResults, strict=True):
                if result.min_distance < best.distance_m:
                    best = Clearance(
                        float(result.min_distance),
                        geometry.geometryObjects[pair.first].name,
                        geometry.geometryObjects[pair.second].name,
                        index,
                    )
        return best


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
