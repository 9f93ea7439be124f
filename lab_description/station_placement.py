"""Where the robot stands at a station and how high it approaches a nest, from the lab's geometry.

Why: a lab integrator measures benches, nests and markers with a tape; the distances the robot keeps
from them follow from those and from the robot model, not from numbers the integrator would have
to tune. The world file may still set them (`poi.standoff`, `poi.work_standoff`, `poi.lateral`,
`nests.approach_height`) as overrides; where it leaves them out, `derive_placement` chooses them,
and `nest_working_pose` moves the base along the bench for a nest outside the arm's band. The
loader's checks (`serviceability`) and the skills read the same functions, and the rules the docs
state are the constants here.

The choice, per station (the base faces the bench, as its heading says):
- working distance: the least that keeps the bench's front edge `WORKING_CLEARANCE` ahead of the
  base (the hotel tray's turning circle and where the final approach may end) and from which the head
  camera sees the marker: the arm reaches higher the nearer the base stands (top-down, at 0.45 m
  from the nest: 0.90 m; at 0.65 m: 0.78 m), and a marker beside the row near the front edge is seen
  too steeply from too near;
- the POI: `FINAL_APPROACH_M` farther back, where navigation stops and the marker is first seen;
- sideways: the row's middle in the middle of the working arm's band, so both ends keep the most
  room for the calibration errors; a nest less than `ARM_SIDE_MARGIN_M` inside the band is worked
  at from a pose moved along the bench that puts it in the band's middle;
- approach height: `PREFERRED_APPROACH_HEIGHT_M`, lowered where the arm cannot reach that high
  above a nest, to no less than the tallest labware type plus `APPROACH_CLEARANCE_M` (the held
  plate's bottom then still clears a neighbour's top).

Pure computation; safe on any thread that owns its own `RobotKinematics`.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from tiago_description import robot_model as rm
from tiago_description import transforms as tf

log = logging.getLogger(__name__)

FINAL_APPROACH_M = 0.22
"""The POI lies this far behind the working pose: the marker-guided final approach drives it. Navigation's
stop error and the odometry drift together have reached 0.18 m."""
PREFERRED_APPROACH_HEIGHT_M = 0.10
"""Above a nest, the tool first comes to this height (the held plate's bottom this far above the floor),
then moves straight down."""
APPROACH_CLEARANCE_M = 0.02
"""The least approach height is the tallest labware type plus this: the held plate passes over a plate
in the next nest."""
APPROACH_HEIGHT_STEP_M = 0.01
VIEW_BACKOFF_M = 0.25
"""The working pose may lie this much farther back than the nearest (m) for the head camera to see the
marker from it."""
VIEW_BACKOFF_STEP_M = 0.01
ARM_SIDE_MARGIN_M = 0.03
"""How far inside the working arm's band a nest must lie (the calibration and approach errors moved
nests up to 1.6 cm across its edge)."""
REACH_ARM = "right"
"""The arm the placement is chosen for (the band of nests it reaches lies on its side)."""


@dataclass(frozen=True)
class Placement:
    """Where the robot stands at a station (m), and which of these the world file set itself."""

    standoff: float
    work_standoff: float
    lateral: float
    approach_height: float
    from_file: frozenset[str] = frozenset()

    def derived(self) -> tuple[str, ...]:
        """The fields the robot chose, in the world file's words (`world check` prints them)."""
        names = ("standoff", "work_standoff", "lateral", "approach_height")
        return tuple(name for name in names if name not in self.from_file)


def nest_distance_behind_front_edge(station, sub_position: int) -> float:  # noqa: ANN001 - a Station
    """How far (m) a nest's centre lies behind its bench's front edge, along the robot's heading."""
    T_table_site = tf.invert(station.T_world_table()) @ station.T_world_site(sub_position)
    return float(T_table_site[0, 3] + station.table_size[0] / 2)


def row_middle_behind_front_edge(station) -> float:  # noqa: ANN001
    """`nest_distance_behind_front_edge` of the row's middle (where the working pose is measured from)."""
    first = nest_distance_behind_front_edge(station, 1)
    last = nest_distance_behind_front_edge(station, station.sub_positions)
    return (first + last) / 2


def least_working_distance(station, working_clearance: float) -> float:  # noqa: ANN001
    """The nearest the base may work in front of the row's middle (m): the bench's front edge then lies
    `working_clearance` ahead of it. Rounded up to the millimetre."""
    return math.ceil((row_middle_behind_front_edge(station) + working_clearance) * 1000) / 1000


def row_length(station) -> float:  # noqa: ANN001
    return (station.sub_positions - 1) * station.spacing


def centred_lateral(station, arm: str = REACH_ARM) -> float:  # noqa: ANN001
    """The base's offset to the left of the row's middle (m) that puts the middle of the row in the middle
    of `arm`'s band (right arm: positive, the nests on its right)."""
    side = 1.0 if arm == "right" else -1.0
    return round(side * rm.TOP_DOWN_REACH_BAND_M / 2, 3)


def approach_heights(tallest_labware_m: float) -> list[float]:
    """The approach heights to try, preferred first, in steps down to the least that clears a neighbour's
    plate, that least one last (an approach 6 mm lower than the last step reached a nest 0.96 m high
    near the base's centre line that the step did not: random layout 193101)."""
    least = math.ceil((tallest_labware_m + APPROACH_CLEARANCE_M) * 1000.0 - 1e-6) / 1000.0  # mm, up
    heights = [max(PREFERRED_APPROACH_HEIGHT_M, least)]  # a plate taller than 8 cm: only the least
    while heights[-1] - APPROACH_HEIGHT_STEP_M >= least - 1e-9:
        heights.append(round(heights[-1] - APPROACH_HEIGHT_STEP_M, 3))
    if heights[-1] - least > 0.001:
        heights.append(least)
    return heights


def nest_working_pose(station, sub_position: int, arm: str) -> np.ndarray:  # noqa: ANN001
    """T_world_base where the robot works at nest ``sub_position``: the station's working pose, or,
    where the nest would lie less than ARM_SIDE_MARGIN_M inside the working arm's band (0 to
    TOP_DOWN_REACH_BAND_M on its side of the base's centre line), that pose moved along the bench
    until the nest lies in the middle of the band (near the centre line the arm reaches less high:
    at 0.60 m ahead, 0.88 m at the band's middle and 0.77 m 3 cm from the line).

    Why: a row may span the whole band or more, its end nests on or past the band's edges, and the
    calibration errors then put one a centimetre beyond: the arm could not reach a nest 0.7 to 1.6 cm
    left of the centre line, 0.78 to 0.84 m high (IK_FAILED), and at the far end, 0.45 m right, the
    fingers closed on a plate pressed into its nest by 45 to 82 N and the grip let go of it
    (PLATE_SLIPPED) (docs/explanation/decisions/working-pose-inside-the-arm-band.md)."""
    T_world_work = station.aligned_pose().matrix()
    side = -1.0 if arm == "right" else 1.0  # the working arm's side of the base, along its y
    inward = side * float((tf.invert(T_world_work) @ station.T_world_site(sub_position))[1, 3])
    if ARM_SIDE_MARGIN_M <= inward <= rm.TOP_DOWN_REACH_BAND_M - ARM_SIDE_MARGIN_M:
        return T_world_work
    wanted = rm.TOP_DOWN_REACH_BAND_M / 2  # the middle of the band: the most room either way
    return T_world_work @ tf.from_planar(0.0, side * (inward - wanted), 0.0)


def nest_working_poses(station, arm: str = REACH_ARM) -> list[tuple[int, np.ndarray]]:  # noqa: ANN001
    """Every nest with the pose it is worked at from (`nest_working_pose`), sub-position 1 first."""
    return [(n, nest_working_pose(station, n, arm)) for n in range(1, station.sub_positions + 1)]


def working_poses(station) -> list[tuple[str, object]]:  # noqa: ANN001
    """The station's working pose and every other pose a nest is worked at from (`nest_working_pose`),
    each with how the messages name it."""
    working = station.aligned_pose()
    poses: list[tuple[str, object]] = [("the working pose", working)]
    for sub_position, T_world_base in nest_working_poses(station):
        x, y, yaw = float(T_world_base[0, 3]), float(T_world_base[1, 3]), working.yaw
        if math.hypot(x - working.x, y - working.y) > 1e-6:
            poses.append((f"the working pose for nest {sub_position}", type(working)(x, y, yaw)))
    return poses
