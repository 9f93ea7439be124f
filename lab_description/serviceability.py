"""Can the TIAGo++ serve this lab? The checks the loader runs after the file's own rules.

Why: a layout the robot cannot physically serve used to fail minutes into a run, as a motion error
at the bench (issue 14). These four checks refuse it before anything moves, from the robot model's
geometry (tiago_description), each with its numbers:

- footprint: the base (radius `BASE_RADIUS`) at the docked pose, or along the straight undock drive to
  the dock's POI, overlaps a bench; at a station's
  working pose the hotel tray's turning circle (`HOTEL_SWEEP_RADIUS`) plus where the marker-guided
  final approach may end (`WORKING_CLEARANCE`) does: that approach drives at the bearing to the
  working pose and turns to the bench there. With bench edges 0.32 to 0.34 m ahead, `Benchtop`, `Tuck`
  and `NestApproach` stopped with head or arm joints off their goals; in a direct reproduction the base
  link, which carries the tray, pressed into the bench with kilonewtons and shook torso and head;
- turning room: the circle the onboard hotel tray sweeps when the base turns at a POI
  (`HOTEL_SWEEP_RADIUS` plus `TURN_MARGIN` for the navigation stop error) reaches a bench, its
  own or another station's (stations too close together);
- reach: no torso height and right-arm configuration puts the grasping frame top-down on a nest
  (grasp and approach height, either finger order), IK on the pinocchio model from the working pose;
- marker view: from the POI and from the working pose, the head camera aimed at the marker cannot
  see it: pan or tilt beyond the head's limits, too near or too far, seen too obliquely, or too small
  in the image.

Pure computation (pinocchio, numpy); safe on any thread that owns its own `RobotKinematics`.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from collections.abc import Iterator
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from lab_description import station_placement as placement
from lab_description.floor_gaps import bench_distance, bench_distances, closest, dock_distances, drive_points
from lab_description.station_placement import working_poses
from tiago_description import robot_model
from tiago_description import transforms as tf
from tiago_description.hotel_model import hotel_sweep_radius
from tiago_description.kinematics import CAMERA_FRAME, head_angles_towards
from tiago_description.reach_map import highest_reached, interpolated_ceiling, reaches_nest
from tiago_description.reach_map import reach_model as _robot
from tiago_description.reach_map import reaches as _reachable

log = logging.getLogger(__name__)

BASE_RADIUS = robot_model.BASE_RADIUS
HOTEL_SWEEP_RADIUS = hotel_sweep_radius()
"""The onboard hotel tray's farthest corner from the base centre (m): the circle a turn sweeps (0.354)."""
TURN_MARGIN = 0.05
"""Navigation stops up to a few cm off its POI (30 mm per axis, one sigma, by default)."""
ALIGN_SIGHTING_ERROR = 0.010
"""How much nearer the bench the working pose the marker shows from the POI may lie than the real one
(m): the head camera's calibration (mount 1 mm and 0.1 deg per axis, head encoder zeros 0.1 deg, depth
bias 1 mm at 1 m; one sigma each) over the 0.7 to 0.9 m to the marker, at three sigma (draws of about
two sigma were measured to give 7 mm)."""
ALIGN_DRIVE_OVERSHOOT = 0.006
"""How far the final approach's drive passes its goal's line towards the bench (m): closing on a goal
beside its heading, the drive curves in and crosses the line by up to 5.6 mm (0.21 m ahead, 0 to
0.1 m aside) before it stops and turns."""
WORKING_CLEARANCE = HOTEL_SWEEP_RADIUS + ALIGN_SIGHTING_ERROR + ALIGN_DRIVE_OVERSHOOT
"""A working pose's least distance from every bench (m): the tray's turning circle, which the final
approach sweeps in part (it drives at the bearing to the working pose, then turns to the bench), plus
where that approach may end: with the circle taken as 0.35 m and no margin, a working pose 0.361 m
from its bench let the tray touch it (the base ended 12 mm nearer than its working pose)."""
REACH_ARM = placement.REACH_ARM
LOOK_TORSO_LIFT = 0.15
"""The torso height the view rule is checked with (m): the travel posture's. The robot looks from the
bench posture's 0.32 m (a drive to a station raises the torso beside it, tiago_skills.drive_posture),
0.17 m higher and a few degrees steeper. Checked at 0.32 m, the rule backs working poses further off
for the view, and their nests then lie at the edge of the arm's reach, where a random-layout campaign
failed more often for IK than it ever did for the view (the benchmarks page, "Standard lab
furniture"); the detector finds the marker well beyond the rule's 60 deg. So the rule stays at the
travel height until the reach near the arm band's edge is made robust: a stated approximation."""
CAMERA_FOCAL_PX = 522.2
MARKER_DISTANCE_RANGE = (0.4, 1.6)
"""Camera to marker centre (m): the camera clips at 0.3 m; beyond 1.5 to 2.5 m detection failed."""
MARKER_MAX_OBLIQUITY_DEG = 60.0
"""Angle between the marker's normal and the line to the camera. The skills' detector, on the simulator's
rendering with camera noise, found the marker in every view up to 75 deg, with the heading error's
95th percentile 0.4 to 0.6 deg up to 65 deg (`python -m tiago_twin.marker_obliquity`); but
65 deg let in stations whose working pose then lay nearer and whose transfers failed in a campaign
(the benchmarks page), so the rule stays at 60 deg until those are understood."""
MARKER_MIN_PIXELS = 40.0
"""Side of the black square in the 640 x 480 image; the pose error grows fast below this."""
CEILING_MARGIN = 0.02
"""A nest this far above `top_down_ceiling` at its (x, y) is out of reach without another IK try (the
map's grid points are found to 5 mm and it is interpolated over 5 cm; neighbouring points differ by
up to 1.5 cm)."""


@dataclass(frozen=True)
class ServiceProblem:
    """A station (index, or -1 for the dock) the robot cannot serve, and why with the numbers."""

    station_index: int
    what: str

    @property
    def where(self) -> str:
        return "dock" if self.station_index < 0 else f"stations[{self.station_index}]"


def place_station(station, tallest_labware_m: float, *, reach: bool = True):  # noqa: ANN001, ANN201 - Station
    """The station with what its world file left to the robot chosen (`station_placement`): the
    working distance from the bench's front edge, the POI behind it, the row centred in the right
    arm's band, and (`reach`) the highest approach height from which the arm reaches every nest."""
    given = station.placement_from_file
    changes: dict[str, float] = {}
    if "lateral" not in given:
        changes["lateral"] = placement.centred_lateral(station)
    if "approach_height" not in given:
        changes["approach_height"] = placement.PREFERRED_APPROACH_HEIGHT_M
    if "work_standoff" not in given:
        if "standoff" in given:
            changes["work_standoff"] = station.standoff
        else:
            changes["work_standoff"] = _nearest_seeing_distance(dataclasses.replace(station, **changes))
    if "standoff" not in given:
        work = changes.get("work_standoff", station.work_standoff)
        changes["standoff"] = round(work + placement.FINAL_APPROACH_M, 3)
    placed = dataclasses.replace(station, **changes)
    if reach and "approach_height" not in given:
        placed = _highest_reachable_approach(placed, tallest_labware_m)
    return placed


def _nearest_seeing_distance(station) -> float:  # noqa: ANN001
    """The least working distance (`least_working_distance`) from which the head camera sees the marker
    from every working pose, up to `placement.VIEW_BACKOFF_M` farther back (the nearest if none: the
    view check then refuses the station). Nearer is better for the arm's reach, which only shrinks
    farther back; a marker beside the row near the bench's front edge is seen too steeply, or too
    near, from the nearest pose."""
    nearest = placement.least_working_distance(station, WORKING_CLEARANCE)
    distance = nearest
    while distance <= nearest + placement.VIEW_BACKOFF_M + 1e-9:
        candidate = dataclasses.replace(station, work_standoff=round(distance, 3))
        if not any(_view_problems(candidate, label, pose) for label, pose in working_poses(candidate)):
            return round(distance, 3)
        distance += placement.VIEW_BACKOFF_STEP_M
    return nearest


def _highest_reachable_approach(station, tallest_labware_m: float):  # noqa: ANN001, ANN202
    """The station with the highest of `approach_heights` from which every nest is reached, found by
    bisection (reach only shrinks as the approach rises); the least of them if none is (the reach
    check then refuses the station, naming it)."""
    heights = placement.approach_heights(tallest_labware_m)  # highest first

    def reached(index: int) -> bool:
        return not _unreached(dataclasses.replace(station, approach_height=heights[index]))

    if reached(0):
        return dataclasses.replace(station, approach_height=heights[0])
    low, high = 0, len(heights) - 1  # heights[low] is not reached; find the first that is
    if not reached(high):
        return dataclasses.replace(station, approach_height=heights[high])
    while high - low > 1:
        middle = (low + high) // 2
        low, high = (low, middle) if reached(middle) else (middle, high)
    log.info("%s: approach height %.2f m, the highest the arm reaches", station.name, heights[high])
    return dataclasses.replace(station, approach_height=heights[high])


def service_problems(world) -> list[ServiceProblem]:  # noqa: ANN001 - a lab.world.World (no import cycle)
    """Every reason the robot cannot serve `world`, station by station (empty: it can)."""
    problems = list(_footprint_problems(world))
    for index, station in enumerate(world.stations):
        problems += [ServiceProblem(index, what) for what in _station_problems(world, station)]
    problems.sort(key=lambda problem: problem.station_index)
    return problems


def _footprint_problems(world) -> Iterator[ServiceProblem]:  # noqa: ANN001
    dock_poses = (("the docked pose", world.dock_pose, BASE_RADIUS),)
    dock_poi = world.pois[world.dock_poi]
    dock_poses += ((f"POI {world.dock_poi}", dock_poi, HOTEL_SWEEP_RADIUS + TURN_MARGIN),)
    for label, pose, radius in dock_poses:
        for station in world.stations:
            yield from (ServiceProblem(-1, what) for what in _clear(label, pose, radius, station))
    yield from (ServiceProblem(-1, what) for what in _undock_problems(world, dock_poi))


def _undock_problems(world, dock_poi) -> Iterator[str]:  # noqa: ANN001
    """The undock drives straight from the docked pose to the dock's POI without turning: the base's
    footprint (the tray lies within it across) plus the navigation error must keep off every bench
    along it: a bench one base radius from that line is grazed although the docked pose and the POI
    are both clear of it."""
    xs, ys = drive_points(world.dock_pose, dock_poi, 20)
    need = BASE_RADIUS + TURN_MARGIN
    for station in world.stations:
        gap, x, y = closest(bench_distances(station, xs, ys), xs, ys)
        if gap < need:
            yield (
                f"the undock drive from the docked pose to POI {world.dock_poi} passes {gap:.3f} m "
                f"from bench {station.name!r} (at x {x:.3f} y {y:.3f} m); the base's "
                f"footprint and the navigation error need {need:.3f} m"
            )


def _clear(label: str, pose, radius: float, station) -> Iterator[str]:  # noqa: ANN001
    gap = bench_distance(station, pose.x, pose.y)
    if gap < radius:
        need = {
            BASE_RADIUS: "its footprint",
            WORKING_CLEARANCE: "the hotel tray's turning circle and the final approach's error",
        }.get(radius, "the hotel tray's turning circle and the navigation error")
        yield (
            f"{label} at x {pose.x:.3f} y {pose.y:.3f} m is {gap:.3f} m from bench {station.name!r}; "
            f"{need} needs {radius:.3f} m"
        )


def station_alone_problems(station, *, advise: bool = True) -> list[str]:  # noqa: ANN001
    """The station's own reasons the robot cannot serve it, whatever else stands in the lab: its nests
    out of reach, its marker out of view, a working pose too near its own bench (a layout generator's
    check of a drawn station before it places it; `advise` as `_reach_problems`)."""
    problems = []
    for label, working in working_poses(station):
        problems += _clear(f"{station.name!r}: the base at {label}", working, WORKING_CLEARANCE, station)
    problems += _reach_problems(station, advise=advise)
    for label, pose in ((f"POI {station.poi}", station.work_pose()), *working_poses(station)):
        problems += _view_problems(station, label, pose)
    return problems


def _station_problems(world, station) -> list[str]:  # noqa: ANN001
    poi = station.work_pose()
    problems: list[str] = []
    for other in world.stations:
        turning = HOTEL_SWEEP_RADIUS + TURN_MARGIN
        problems += _clear(f"{station.name!r}: the base at POI {station.poi}", poi, turning, other)
        for label, working in working_poses(station):
            problems += _clear(f"{station.name!r}: the base at {label}", working, WORKING_CLEARANCE, other)
    problems += list(_dock_problems(world, station))
    problems += _reach_problems(station)
    for label, pose in ((f"POI {station.poi}", poi), *working_poses(station)):
        problems += _view_problems(station, label, pose)
    return problems


def _dock_problems(world, station) -> Iterator[str]:  # noqa: ANN001
    """The final approach drives straight from the station's POI to the pose a nest is worked at from,
    and from one such pose to the next: the base's footprint plus the navigation error must keep off
    the dock all along (it stands lower than the tray and the folded arms). A pose moved along the
    bench for an end nest has ended 0.16 m from the dock: the base drove into it, slid off, and swung
    the tray into the bench."""
    need = BASE_RADIUS + TURN_MARGIN
    stops = [(f"POI {station.poi}", station.work_pose()), *working_poses(station)]
    for i, (start_label, start) in enumerate(stops):
        for end_label, end in stops[i + 1 :]:
            xs, ys = drive_points(start, end, 10)
            gap, x, y = closest(dock_distances(world.dock_pose, xs, ys), xs, ys)
            if gap < need:
                yield (
                    f"{station.name!r}: the drive from {start_label} to {end_label} passes {gap:.3f} m "
                    f"from the dock (at x {x:.3f} y {y:.3f} m); the base's footprint and the navigation "
                    f"error need {need:.3f} m: move the dock or the station"
                )
                return  # one line per station: the dock stands where the robot works


def _reach_problems(station, *, advise: bool = True) -> list[str]:  # noqa: ANN001
    """Each nest out of reach, with (`advise`) how high the arm reaches there: that costs IK at the
    edge of the reach map, which a generator that only wants to know whether does without."""
    problems = []
    for sub_position, label, height, (x, y, z) in _unreached(station):
        advice = f"; {_reach_advice(station, x, y, z)}" if advise else ""
        problems.append(
            f"{station.name!r}: nest {sub_position} is out of the {REACH_ARM} arm's reach at "
            f"any torso height ({label}, {height * 1000:.0f} mm above the nest: x {x:.3f} y {y:.3f} "
            f"z {z:.3f} m in the working pose's base_footprint){advice}"
        )
    return problems


def _unreached(station) -> list[tuple[int, str, float, tuple[float, float, float]]]:  # noqa: ANN001
    """Each nest the arm does not reach top-down from its working pose: the sub-position, what is out of
    reach (the grasp or the approach) and how high above the nest, and the nest in base_footprint.
    A nest well above the highest one the arm reaches there (`top_down_ceiling`) is refused without
    trying IK once more."""
    unreached = []
    for sub_position, T_world_base in placement.nest_working_poses(station):
        T_base_site = tf.levelled(tf.invert(T_world_base) @ station.T_world_site(sub_position))
        x, y, z = (float(v) for v in T_base_site[:3, 3])
        key = (round(x, 4), round(y, 4), round(z, 4), round(tf.yaw_of(T_base_site), 4))
        label = _nest_unreached(*key, round(station.approach_height, 4))
        if label is not None:
            height = 0.0 if label == "the grasp" else station.approach_height
            unreached.append((sub_position, label, height, (x, y, z)))
    return unreached


@lru_cache(maxsize=16384)
def _nest_unreached(x: float, y: float, z: float, yaw: float, approach_height: float) -> str | None:
    """What of a nest at (x, y, z, yaw) in base_footprint the arm does not reach top-down: "the grasp",
    "the approach" (`approach_height` above it), or None. Cached: the loader and a layout generator ask
    about the same nest relative to its working pose again and again."""
    ceiling = top_down_ceiling(x, y, approach_height)  # None: the map cannot tell
    if ceiling is not None and z > ceiling + CEILING_MARGIN:
        return "the approach"
    kinematics, grasp, seed = _robot()
    T_base_site = tf.from_planar(x, y, yaw, z)
    for label, height in (("the grasp", 0.0), ("the approach", approach_height)):
        T_base_grasp = T_base_site @ tf.make_transform((0.0, 0.0, height)) @ grasp.T_slot_grasp(False)
        if not _reachable(kinematics, T_base_grasp, seed):
            return label
    return None


def _reach_advice(station, x: float, y: float, z: float) -> str:  # noqa: ANN001
    """What would make a nest at (x, y, z) in the working pose's base_footprint reachable: the highest
    nest the arm reaches top-down this far ahead, and how near the front edge the base may stand."""
    ceiling = top_down_ceiling(x, y, station.approach_height)
    if ceiling is None:  # at the edge of the map: ask the model itself
        grasp_ceiling = highest_reached(lambda height: reaches_nest(x, y, height))
        ceiling = None if grasp_ceiling is None else grasp_ceiling - station.approach_height
    nearest = placement.least_working_distance(station, WORKING_CLEARANCE)
    reach = (
        f"from here the arm reaches a nest up to {math.floor(ceiling * 100) / 100:.2f} m above the floor"
        if ceiling is not None
        else "the arm reaches no nest there at any height"
    )
    return (
        f"{reach}; lower the nest, or bring the row nearer the bench's front edge (the base may work "
        f"as near as {nearest:.2f} m from this row, its front edge then {WORKING_CLEARANCE:.2f} m ahead)"
    )


def top_down_ceiling(x: float, y: float, approach_height: float) -> float | None:
    """The highest nest (its floor above the floor, m) that the arm reaches top-down, grasp and approach,
    at (x, y) in base_footprint; None if none from 0.3 m up. The approach `approach_height` above a
    nest is the grasp of a nest that much higher, so this is `top_down_grasp_ceiling` less it."""
    ceiling = top_down_grasp_ceiling(x, y)
    if ceiling is None:
        return None
    return ceiling - approach_height


def top_down_grasp_ceiling(x: float, y: float) -> float | None:
    """The highest nest floor (m above the floor) whose top-down grasp the arm reaches at (x, y) in
    base_footprint at any torso height (`tiago_description.reach_map`, interpolated); None if none."""
    return interpolated_ceiling(x, y)


def _view_problems(station, label: str, pose) -> list[str]:  # noqa: ANN001
    kinematics, _grasp, _seed = _robot()
    T_base_marker = tf.invert(pose.matrix()) @ station.T_world_marker()
    target = T_base_marker[:3, 3]
    aim = head_angles_towards(kinematics, {"torso_lift_joint": LOOK_TORSO_LIFT}, target)
    pan, tilt = aim["head_1_joint"], aim["head_2_joint"]
    head = {joint.name: joint.limits_deg for joint in robot_model.HEAD_JOINTS}
    joints = {"torso_lift_joint": LOOK_TORSO_LIFT, "head_1_joint": pan, "head_2_joint": tilt}
    camera = kinematics.forward(joints, CAMERA_FRAME)[:3, 3]
    to_camera = camera - target
    distance = float(np.linalg.norm(to_camera))
    obliquity = math.degrees(math.acos(np.clip(T_base_marker[:3, 2] @ to_camera / distance, -1.0, 1.0)))
    pixels = CAMERA_FOCAL_PX * station.marker_size / distance
    reasons = []
    for name, angle in (("head_1", pan), ("head_2", tilt)):
        low, high = head[name]
        if not low <= math.degrees(angle) <= high:
            reasons.append(f"{name} would need {math.degrees(angle):.0f} deg (limits {low:g} .. {high:g})")
    if not MARKER_DISTANCE_RANGE[0] <= distance <= MARKER_DISTANCE_RANGE[1]:
        low, high = MARKER_DISTANCE_RANGE
        reasons.append(f"the marker is {distance:.2f} m from the camera (usable {low:g} .. {high:g} m)")
    if obliquity > MARKER_MAX_OBLIQUITY_DEG:
        reasons.append(
            f"the marker is seen {obliquity:.0f} deg off its face's normal "
            f"(at most {MARKER_MAX_OBLIQUITY_DEG:g})"
        )
    elif pixels < MARKER_MIN_PIXELS:
        reasons.append(f"the marker is {pixels:.0f} px wide in the image (at least {MARKER_MIN_PIXELS:g})")
    if not reasons:
        return []
    seeing = f"{station.name!r}: the head camera cannot see marker {station.marker_id} from {label}"
    return [f"{seeing}: " + "; ".join(reasons)]
