"""The head's aim stays inside its joint limits, by a degree, and is left alone inside them.

Why: the final approach aimed the head at a low, near marker with a tilt 0.2 deg beyond the tilt
limit; the head stopped at the limit and the motion failed as "did not reach the goal" (random
layout 134099), though the marker was well inside the image from there.
"""

from __future__ import annotations

import math

import pytest

from tiago_description.kinematics import (
    HEAD_LIMIT_MARGIN_RAD,
    RobotKinematics,
    head_angles_towards,
    within_head_limits,
)
from tiago_description.robot_model import HEAD_JOINTS

LIMITS = {f"{joint.name}_joint": tuple(map(math.radians, joint.limits_deg)) for joint in HEAD_JOINTS}


def test_an_aim_beyond_a_limit_is_held_a_degree_inside_it() -> None:
    low_tilt, _ = LIMITS["head_2_joint"]
    _, high_pan = LIMITS["head_1_joint"]
    held = within_head_limits({"head_1_joint": high_pan + 0.3, "head_2_joint": low_tilt - 0.0035})
    assert held["head_1_joint"] == pytest.approx(high_pan - HEAD_LIMIT_MARGIN_RAD)
    assert held["head_2_joint"] == pytest.approx(low_tilt + HEAD_LIMIT_MARGIN_RAD)


def test_an_aim_inside_the_limits_is_unchanged() -> None:
    aim = head_angles_towards(RobotKinematics(), {"torso_lift_joint": 0.15}, [1.0, -0.2, 0.9])
    assert within_head_limits(aim) == aim
