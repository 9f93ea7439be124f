"""Folding the arm (Tuck) from over the onboard hotel: where the finger pads sweep.

Why: at a working pose a bench's front edge stands 0.36 .. 0.45 m ahead of the base centre, its top
up to 0.78 m high (README "Random layouts"). Folding in joint space from the hotel's approach pose
swung the pads forward over that edge at its height (random layout 91089: Tuck after GetLabware
grazed the incubator's edge); from the carry height above the hotel they stay above every bench top.
The sweep is the arm controller's: joints interpolated linearly from start to goal.
"""

from __future__ import annotations

import numpy as np
import pytest

from tiago_description import robot_model as rm
from tiago_description.kinematics import RobotKinematics
from tiago_description.motion_library import load_motions

ARM = "right"
NEAREST_BENCH_EDGE_M = 0.36  # ahead of the base centre at a working pose
HIGHEST_BENCH_TOP_M = 0.78
FLIP = np.diag([1.0, -1.0, -1.0, 1.0])  # the grasp's twin (grasp_twins.FLIP_ABOUT_APPROACH)


@pytest.fixture(scope="module")
def kinematics() -> RobotKinematics:
    return RobotKinematics()


def pad_corners(kinematics: RobotKinematics, joints: dict[str, float]) -> np.ndarray:
    """The corners of both finger pads in base_footprint (robot_model's finger geometry)."""
    tip = 0.12 + rm.PAD_TIP
    corners = []
    for finger, sign in (("left", 1.0), ("right", -1.0)):
        T = kinematics.forward(joints, f"gripper_{ARM}_{finger}_finger_link")
        inner = sign * (rm.FINGER_MOUNT_OFFSET + rm.PAD_THICKNESS / 2)
        for dx in (tip - rm.PAD_LENGTH, tip):
            for dy in (-rm.PAD_THICKNESS / 2, rm.PAD_THICKNESS / 2):
                for dz in (-rm.PAD_WIDTH / 2, rm.PAD_WIDTH / 2):
                    corners.append((T @ np.array([dx, inner + dy, dz, 1.0]))[:3])
    return np.array(corners)


def lowest_pad_ahead(kinematics: RobotKinematics, start: dict[str, float], goal: dict[str, float]) -> float:
    """The lowest height a pad corner reaches ahead of the nearest bench edge on the way (inf: never)."""
    lowest = np.inf
    for t in np.linspace(0.0, 1.0, 81):
        joints = {name: value + (goal.get(name, value) - value) * t for name, value in start.items()}
        corners = pad_corners(kinematics, joints)
        ahead = corners[corners[:, 0] > NEAREST_BENCH_EDGE_M]
        if len(ahead):
            lowest = min(lowest, float(ahead[:, 2].min()))
    return lowest


def hotel_start(
    kinematics: RobotKinematics, slot: int, flip: bool, raise_m: float, torso: float
) -> dict[str, float] | None:
    """Joints with the open gripper at the approach of a hotel slot, ``raise_m`` above it."""
    motions = load_motions()
    seed: dict[str, float] = {}
    for frame in motions.frames_for("Benchtop", ARM):
        seed.update(frame)
    seed.update(
        {"torso_lift_joint": torso, **{name: rm.FINGER_TRAVEL for name in rm.finger_joint_names(ARM)}}
    )
    T = kinematics.forward({}, f"hotel_slot_{slot}") @ motions.hotel.T_slot_grasp(approach=True)
    T[2, 3] += raise_m
    result = kinematics.inverse(ARM, T @ FLIP if flip else T, seed, use_torso=False, restarts=40)
    return {**seed, **result.joint_positions} if result.success else None


def test_folding_from_the_hotel_approach_sweeps_the_pads_over_a_bench_edge(
    kinematics: RobotKinematics,
) -> None:
    """The cause of 91089: the pads pass ahead of the nearest bench edge below the highest bench top
    (at some torso height the straight moves before may leave). 91089's plate was in the pocket on
    the right arm's side, slot 2 since the left one is slot 1."""
    tuck = load_motions().frames_for("Tuck", ARM)[0]
    starts = [hotel_start(kinematics, 2, False, 0.0, torso) for torso in (0.15, 0.2, 0.25)]
    lowest = min(lowest_pad_ahead(kinematics, start, tuck) for start in starts if start is not None)
    assert lowest < HIGHEST_BENCH_TOP_M


@pytest.mark.parametrize("torso", [0.25, 0.35])
@pytest.mark.parametrize("slot", [1, 2])
def test_folding_from_the_carry_height_keeps_the_pads_above_every_bench_top(
    kinematics: RobotKinematics, torso: float, slot: int
) -> None:
    """What play_motion does now: rise to the carry height over the hotel (leave_hotel), then fold,
    from whichever grasp twin the arm reaches there (one of them always is)."""
    motions = load_motions()
    starts = [
        hotel_start(kinematics, slot, flip, motions.hotel.carry_height_m, torso) for flip in (False, True)
    ]
    reachable = [start for start in starts if start is not None]
    assert reachable, "neither grasp twin over the hotel is in reach"
    tuck = motions.frames_for("Tuck", ARM)[0]
    for start in reachable:
        assert lowest_pad_ahead(kinematics, start, tuck) > HIGHEST_BENCH_TOP_M + 0.05
