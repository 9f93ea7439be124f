"""Seeded disturbances for repeatability campaigns: the failure sources field reports name.

Why: the published TIAGo++ and mobile-manipulator transfer studies lost runs to navigation drift on
uneven floors and to placements off by millimetres. A campaign must show our success rate under
the same kinds of error, drawn afresh per trial but reproducible from one seed.

Model: two worlds come out of one nominal world. The *true* world (what PyBullet builds) has its
stations moved on the floor, each marker glued slightly off its nominal place on the stand, and
each nest row mounted slightly off; the nests stay put when only the marker moves, so the
robot's calibrated site-in-marker transform is wrong by exactly the marker error. The *believed*
world (what the robot's behaviours read: POIs, marker ids, site-in-marker) is the nominal one,
except that every station POI is shifted: the base stops off the pose the station expects, as
it does after a real navigation with localisation error. Odometry drift (wheel radius error plus
per-step slip), camera noise (colour and depth, camera_noise), plate mass/friction spread, the
robot's calibration errors and failing identity reads act inside the Simulation.

Calibration (the true robot differs from the model the robot software keeps, the URDF both load):
the head camera sits on the head off its modelled mount (hand-eye error: a rigid offset of the
optical frame, drawn per axis), and every arm and head joint's encoder zero is off by a constant
(its reading is the true angle plus the offset). Both are applied on the simulation side
(``Simulation.T_camera_mount_error``, ``RobotBody.encoder_offsets``), so FK from joint readings
and the nominal camera frame, as the robot software computes it, is off by what they imply.
The torso lift's zero is not disturbed: it moves camera and arms together, so it cancels in
every marker-relative move.

Levels are standard deviations (SI: m, rad; camera noise in 8-bit grey levels; spreads relative);
every draw is clipped at 3 sigma so a rare draw stays a physically plausible one.
Pure functions except ``apply_to_simulation`` (sim thread: it touches the PyBullet client).
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lab_description.world import Pose2D, Station, World
from tiago_description import robot_model
from tiago_description import transforms as tf
from tiago_sim.measuring.camera_noise import noisy_camera

log = logging.getLogger(__name__)

CLIP_SIGMAS = 3.0
# Joints whose encoder zero is off (the torso lift is not: see the module docstring).
CALIBRATED_JOINTS = (
    *robot_model.arm_joint_names("right"),
    *robot_model.arm_joint_names("left"),
    "head_1_joint",
    "head_2_joint",
)


@dataclass(frozen=True)
class DisturbanceLevels:
    """One standard deviation per failure source; defaults are the campaign's default level.

    Rationale for the defaults:
    - navigation 3 cm / 2 deg: AMCL-style localisation on a lab floor ends within a few cm and
      degrees of the goal (the TIAGo++ study's main failure source, worse on uneven floors).
    - odometry 0.2 %: wheel radius error and slip per wheel; tiles and thresholds make it
      several times the factory 0.05 %.
    - station 1 cm / 1 deg: a bench nudged since the map was drawn.
    - marker 1 mm / 0.5 deg: a marker stuck on by hand against a printed template.
    - nest 1 mm / 0.3 deg: nests screwed down with slotted holes (the "off by millimetres" case).
    - camera 2 grey levels: read noise of a consumer RGB-D camera in lab light.
    - plate mass 10 %, friction 15 %: filled versus empty plates, different polystyrene batches.
    - depth noise 1.9 mm at 1 m (growing with distance, see camera_noise): a structured-light
      RGB-D camera's axial noise as Nguyen et al. measured it on a Kinect; depth bias 1 mm at 1 m
      per trial: what the depth calibration (and disparity quantisation) leaves.
    - camera mount 1 mm and 0.1 deg per axis: what a careful hand-eye calibration leaves.
    - joint offsets 0.1 deg per arm and head joint: encoder zeros after a factory calibration.
    - identity reads 0.1 % failed: fixed-mount barcode readers on clean labels read 99.9 % or
      better on the first try; worn or skewed labels read worse.
    - bench height 1 mm: the top's height as an integrator measures it with a tape for the world
      file. The robot takes a nest's height from the file's bench (not from the marker, whose
      sighting is a few millimetres off in height), so this error goes straight into the grasp.
    """

    navigation_xy_m: float = 0.03
    navigation_yaw_rad: float = math.radians(2.0)
    odometry_noise: float = 0.002
    station_xy_m: float = 0.01
    station_yaw_rad: float = math.radians(1.0)
    marker_xy_m: float = 0.001
    marker_yaw_rad: float = math.radians(0.5)
    nest_xy_m: float = 0.001
    nest_yaw_rad: float = math.radians(0.3)
    camera_noise: float = 2.0
    plate_mass_spread: float = 0.10
    plate_friction_spread: float = 0.15
    depth_noise_m: float = 0.0019  # per-pixel sigma at 1 m
    depth_bias_m: float = 0.001  # per-trial bias sigma at 1 m
    camera_mount_xyz_m: float = 0.001
    camera_mount_rpy_rad: float = math.radians(0.1)
    joint_offset_rad: float = math.radians(0.1)
    id_read_failure: float = 0.001  # probability that one read of a plate's label fails
    bench_height_m: float = 0.001  # the bench top's true height less the world file's

    def scaled(self, factor: float) -> DisturbanceLevels:
        """Every level times `factor` (0 gives an undisturbed world)."""
        return DisturbanceLevels(**{k: v * factor for k, v in dataclasses.asdict(self).items()})

    def to_json(self) -> str:
        return json.dumps(dataclasses.asdict(self), sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> DisturbanceLevels:
        values = json.loads(text)
        unknown = set(values) - {f.name for f in dataclasses.fields(cls)}
        if unknown:
            raise ValueError(f"unknown disturbance levels: {sorted(unknown)}")
        return cls(**{k: float(v) for k, v in values.items()})


@dataclass(frozen=True)
class PlanarOffset:
    """A small rigid error in a plane: x, y (m) and rotation about the plane's normal (rad)."""

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0

    def matrix(self) -> np.ndarray:
        return tf.from_planar(self.x, self.y, self.yaw)

    def human(self) -> dict[str, float]:
        """mm and degrees, rounded, for logs and reports."""
        return {
            "x_mm": round(1000 * self.x, 2),
            "y_mm": round(1000 * self.y, 2),
            "yaw_deg": round(math.degrees(self.yaw), 3),
        }


@dataclass(frozen=True)
class TrialDisturbance:
    """The concrete draws of one trial (all from `seed`)."""

    seed: int
    levels: DisturbanceLevels
    navigation: dict[str, PlanarOffset] = field(default_factory=dict)  # POI name -> base stop error
    station: dict[str, PlanarOffset] = field(default_factory=dict)  # table pose error (floor plane)
    marker: dict[str, PlanarOffset] = field(default_factory=dict)  # in the marker plane
    nest: dict[str, PlanarOffset] = field(default_factory=dict)  # nest row, in the site plane
    plate_mass_factor: dict[str, float] = field(default_factory=dict)
    plate_friction_factor: dict[str, float] = field(default_factory=dict)
    camera_mount: tuple[float, ...] = (0.0,) * 6  # x, y, z (m), roll, pitch, yaw (rad) in the optical frame
    joint_offsets: dict[str, float] = field(default_factory=dict)  # joint -> reading minus truth (rad)
    depth_bias_m: float = 0.0  # at 1 m, growing with distance squared
    bench_height: dict[str, float] = field(default_factory=dict)  # station -> true less file height (m)

    def T_camera_mount_error(self) -> np.ndarray:
        """The true optical frame in the modelled one."""
        x, y, z, roll, pitch, yaw = self.camera_mount
        return tf.from_xyz_rpy((x, y, z), (roll, pitch, yaw))

    def summary(self) -> dict[str, Any]:
        """JSON-ready description in mm/deg (what a failure log shows next to the seed)."""

        def offsets(table: dict[str, PlanarOffset]) -> dict[str, dict[str, float]]:
            return {name: offset.human() for name, offset in table.items()}

        return {
            "seed": self.seed,
            "navigation": offsets(self.navigation),
            "station": offsets(self.station),
            "marker": offsets(self.marker),
            "nest": offsets(self.nest),
            "plate_mass_factor": {k: round(v, 3) for k, v in self.plate_mass_factor.items()},
            "plate_friction_factor": {k: round(v, 3) for k, v in self.plate_friction_factor.items()},
            "camera_mount_mm_deg": [round(1000 * v, 2) for v in self.camera_mount[:3]]
            + [round(math.degrees(v), 3) for v in self.camera_mount[3:]],
            "joint_offsets_deg": {k: round(math.degrees(v), 3) for k, v in self.joint_offsets.items()},
            "depth_bias_mm_at_1m": round(1000 * self.depth_bias_m, 2),
            "bench_height_mm": {k: round(1000 * v, 2) for k, v in self.bench_height.items()},
        }


def _clipped_normal(rng: np.random.Generator, sigma: float) -> float:
    if sigma <= 0.0:
        rng.standard_normal()  # keep the stream aligned whatever the levels
        return 0.0
    return float(np.clip(rng.standard_normal(), -CLIP_SIGMAS, CLIP_SIGMAS) * sigma)


def _offset(rng: np.random.Generator, xy_sigma: float, yaw_sigma: float) -> PlanarOffset:
    return PlanarOffset(
        _clipped_normal(rng, xy_sigma), _clipped_normal(rng, xy_sigma), _clipped_normal(rng, yaw_sigma)
    )


def draw(world: World, seed: int, levels: DisturbanceLevels) -> TrialDisturbance:
    """All draws of one trial, in a fixed order (stations, then plates, as the world lists them)."""
    rng = np.random.default_rng(seed)
    navigation, station, marker, nest = {}, {}, {}, {}
    for s in world.stations:
        navigation[s.poi] = _offset(rng, levels.navigation_xy_m, levels.navigation_yaw_rad)
        station[s.name] = _offset(rng, levels.station_xy_m, levels.station_yaw_rad)
        marker[s.name] = _offset(rng, levels.marker_xy_m, levels.marker_yaw_rad)
        nest[s.name] = _offset(rng, levels.nest_xy_m, levels.nest_yaw_rad)
    mass, friction = {}, {}
    for plate in world.plates:  # the keys, in the file's order
        mass[plate.labware_id] = 1.0 + _clipped_normal(rng, levels.plate_mass_spread)
        friction[plate.labware_id] = 1.0 + _clipped_normal(rng, levels.plate_friction_spread)
    # The calibration draws have their own stream: adding them left every earlier draw of a seed as it was.
    calibration = np.random.default_rng([seed, 0xCA11B])
    mount = tuple(_clipped_normal(calibration, levels.camera_mount_xyz_m) for _ in range(3)) + tuple(
        _clipped_normal(calibration, levels.camera_mount_rpy_rad) for _ in range(3)
    )
    offsets = {name: _clipped_normal(calibration, levels.joint_offset_rad) for name in CALIBRATED_JOINTS}
    depth_bias = _clipped_normal(calibration, levels.depth_bias_m)
    measured = np.random.default_rng([seed, 0xBE4C])  # a stream of its own, as the calibration's
    heights = {s.name: _clipped_normal(measured, levels.bench_height_m) for s in world.stations}
    return TrialDisturbance(
        seed, levels, navigation, station, marker, nest, mass, friction, mount, offsets, depth_bias, heights
    )


def _xyz_rpy(transform: np.ndarray) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """Inverse of tf.from_xyz_rpy (R = Rz Ry Rx); pitch stays away from +-90 deg for our frames."""
    rotation = transform[:3, :3]
    pitch = math.asin(-max(-1.0, min(1.0, rotation[2, 0])))
    roll = math.atan2(rotation[2, 1], rotation[2, 2])
    yaw = math.atan2(rotation[1, 0], rotation[0, 0])
    x, y, z = (float(v) for v in transform[:3, 3])
    return (x, y, z), (roll, pitch, yaw)


def _true_station(station: Station, disturbance: TrialDisturbance) -> Station:
    moved, marker_error, nest_error = (
        disturbance.station[station.name],
        disturbance.marker[station.name],
        disturbance.nest[station.name],
    )
    table = station.table_pose
    c, s = math.cos(table.yaw), math.sin(table.yaw)
    table_pose = Pose2D(
        table.x + c * moved.x - s * moved.y, table.y + s * moved.x + c * moved.y, table.yaw + moved.yaw
    )
    T_table_marker = station.T_table_marker() @ marker_error.matrix()
    # nests stay on the table when only the marker is off; then the row itself is off by nest_error
    T_marker_site = tf.invert(marker_error.matrix()) @ station.T_marker_site(1) @ nest_error.matrix()
    marker_xyz, marker_rpy = _xyz_rpy(T_table_marker)
    site_xyz, site_rpy = _xyz_rpy(T_marker_site)
    depth, width, height = station.table_size  # marker and nests stand on the top: they rise with it
    return dataclasses.replace(
        station,
        table_pose=table_pose,
        table_size=(depth, width, height + disturbance.bench_height.get(station.name, 0.0)),
        marker_xyz=marker_xyz,
        marker_rpy=marker_rpy,
        site_xyz=site_xyz,
        site_rpy=site_rpy,
    )


def true_world(world: World, disturbance: TrialDisturbance) -> World:
    """The world PyBullet builds: stations, markers and nests where they really are."""
    stations = tuple(_true_station(station, disturbance) for station in world.stations)
    return dataclasses.replace(world, stations=stations)


def believed_world(world: World, disturbance: TrialDisturbance) -> World:
    """The world the robot's behaviours read: nominal, but each station POI is where the base stops."""
    pois = dict(world.pois)
    for name, error in disturbance.navigation.items():
        pose = pois[name]
        c, s = math.cos(pose.yaw), math.sin(pose.yaw)
        pois[name] = Pose2D(
            pose.x + c * error.x - s * error.y, pose.y + s * error.x + c * error.y, pose.yaw + error.yaw
        )
    return dataclasses.replace(world, pois=pois)


def apply_to_simulation(sim: Any, disturbance: TrialDisturbance) -> None:
    """Plate spreads, camera noise, calibration errors and identity readers on a built Simulation
    (sim thread)."""
    import pybullet as p  # only the sim process needs PyBullet

    from tiago_sim.physics.identity_readers import IdentityReaders

    for labware_id, body in sim.scene.plates.items():
        mass = sim.scene.plate_types[labware_id].mass * disturbance.plate_mass_factor.get(labware_id, 1.0)
        friction = p.getDynamicsInfo(body, -1, physicsClientId=sim.client_id)[1]
        friction *= disturbance.plate_friction_factor.get(labware_id, 1.0)
        p.changeDynamics(body, -1, mass=mass, lateralFriction=friction, physicsClientId=sim.client_id)
    levels = disturbance.levels
    sim.render_head_camera = noisy_camera(
        sim.render_head_camera,
        levels.camera_noise,
        disturbance.seed,
        depth_sigma_at_1m=levels.depth_noise_m,
        depth_bias_at_1m=disturbance.depth_bias_m,
    )
    sim.T_camera_mount_error = disturbance.T_camera_mount_error()
    sim.robot.set_encoder_offsets(disturbance.joint_offsets)
    sim.plate_sensing.readers = IdentityReaders(levels.id_read_failure, disturbance.seed)
    log.info("disturbances applied: %s", json.dumps(disturbance.summary()))
