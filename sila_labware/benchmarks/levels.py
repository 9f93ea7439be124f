"""The campaigns' disturbance levels as flags: human units on the command line, SI for the sim node.

Why apart: the bench's flags, their defaults and the real-robot preset are one table that the CLI,
the campaign and the reports read; the sim node reads the same levels as JSON in SI units
(tiago_sim.measuring.disturbances, which gives each default's rationale). Pure.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass


@dataclass(frozen=True)
class LevelFlag:
    """One disturbance level: CLI flag in human units, its SI field for the sim node, the default."""

    flag: str
    field: str
    to_si: float  # multiply the flag value by this to get the SI value
    default: float  # in the flag's unit
    help: str


LEVEL_FLAGS = (
    LevelFlag("--nav-error-mm", "navigation_xy_m", 1e-3, 30.0, "base stop error after navigation, per axis"),
    LevelFlag(
        "--nav-error-deg", "navigation_yaw_rad", math.pi / 180, 2.0, "base heading error after navigation"
    ),
    LevelFlag("--odometry-noise-pct", "odometry_noise", 1e-2, 0.2, "wheel radius error and slip per wheel"),
    LevelFlag("--station-error-mm", "station_xy_m", 1e-3, 10.0, "station (table) placement error, per axis"),
    LevelFlag("--station-error-deg", "station_yaw_rad", math.pi / 180, 1.0, "station heading error"),
    LevelFlag("--marker-error-mm", "marker_xy_m", 1e-3, 1.0, "marker mounted off its place, per axis"),
    LevelFlag("--marker-error-deg", "marker_yaw_rad", math.pi / 180, 0.5, "marker rotated in its plane"),
    LevelFlag("--nest-error-mm", "nest_xy_m", 1e-3, 1.0, "nest row mounted off its place, per axis"),
    LevelFlag("--nest-error-deg", "nest_yaw_rad", math.pi / 180, 0.3, "nest row rotated on the table"),
    LevelFlag("--camera-noise", "camera_noise", 1.0, 2.0, "head camera read noise, 8-bit grey levels"),
    LevelFlag("--plate-mass-pct", "plate_mass_spread", 1e-2, 10.0, "plate mass spread"),
    LevelFlag("--plate-friction-pct", "plate_friction_spread", 1e-2, 15.0, "plate friction spread"),
    LevelFlag("--depth-noise-mm", "depth_noise_m", 1e-3, 1.9, "depth noise per pixel at 1 m (~z^2)"),
    LevelFlag("--depth-bias-mm", "depth_bias_m", 1e-3, 1.0, "depth bias per trial at 1 m (~z^2)"),
    LevelFlag("--camera-mount-mm", "camera_mount_xyz_m", 1e-3, 1.0, "hand-eye error of the camera, per axis"),
    LevelFlag(
        "--camera-mount-deg", "camera_mount_rpy_rad", math.pi / 180, 0.1, "hand-eye rotation error, per axis"
    ),
    LevelFlag(
        "--joint-offset-deg", "joint_offset_rad", math.pi / 180, 0.1, "encoder zero error per arm/head joint"
    ),
    LevelFlag("--id-read-failure-pct", "id_read_failure", 1e-2, 0.1, "chance that a barcode read fails"),
    LevelFlag("--bench-height-error-mm", "bench_height_m", 1e-3, 1.0, "bench top higher than the world file"),
)


# --real-robot: a drive ends anywhere a robot's navigation stack allows. Nav2's default goal checker
# (nav2_controller's SimpleGoalChecker) counts a goal reached within xy_goal_tolerance 0.25 m and
# yaw_goal_tolerance 0.25 rad. Draws are clipped at 3 sigma per axis (disturbances.CLIP_SIGMAS), so
# 0.25 / (3 sqrt 2) m per axis puts a corner draw 0.25 m off, and 0.25 / 3 rad the heading's extreme
# at 0.25 rad: every stop lies within the tolerances, and the extremes reach them.
NAV2_XY_GOAL_TOLERANCE_M = 0.25
NAV2_YAW_GOAL_TOLERANCE_RAD = 0.25
CLIP_SIGMAS = 3.0
REAL_ROBOT_LEVELS = {  # in the flags' units
    "navigation_xy_m": NAV2_XY_GOAL_TOLERANCE_M / (CLIP_SIGMAS * math.sqrt(2.0)) * 1e3,
    "navigation_yaw_rad": math.degrees(NAV2_YAW_GOAL_TOLERANCE_RAD / CLIP_SIGMAS),
}


def levels_json(values: dict[str, float]) -> str:
    """Flag values (keyed by SI field name, human units) -> the sim node's --disturbance-levels."""
    return json.dumps(
        {level.field: values[level.field] * level.to_si for level in LEVEL_FLAGS}, sort_keys=True
    )


def default_level_values(scale: float = 1.0) -> dict[str, float]:
    return {level.field: level.default * scale for level in LEVEL_FLAGS}
