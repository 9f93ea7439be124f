"""MarkerMotion: move the tool to a nest located from the station's ArUco marker (robot software).

Why this is robot software and not simulation: it uses only what a real TIAGo has - the head
camera's pixels and depth, its joint readings and its kinematic model. The marker pose comes from
perception.detect_marker on the rendered image; the camera pose in base_footprint from forward
kinematics of the joint readings taken with the image; never from simulator link states.

Target "work_pose" moves the base instead (tiago_skills.base_alignment): from the station's POI to
the working pose in front of the nests, as the marker shows it; with the hand empty, it then reads
where a plate lies in the nest, and a pick grasps it there (tiago_skills.pick_correction).
Target "inspect" moves nothing but the head: it reads from the depth image whether a plate lies in
the nest, the check of a lab whose nests have no sensors. Both looks into a nest are
tiago_skills.nest_looks.

Steps: take an image (the hardware port) -> detect the marker (this thread) -> T_base_marker =
T_base_optical @ T_optical_marker -> the nest frame from the world's site_in_marker, sub-position
spacing and approach height -> the grasp pose in that frame (fingers down, closing across the
plate's short side; the flipped twin if IK prefers it) -> a way there clear of the marker's board
(bench_route: a straight tool line where it is clear). A sighting is
reused while the base has not moved: the marker is fixed to its station, so its pose in
base_footprint holds whatever arms, torso and head do since (and the arm above the nest hides the
marker from the head). Lives on: an rclpy executor thread (one goal at a time).
"""

from __future__ import annotations

import dataclasses
import logging
import threading
from collections.abc import Callable
from typing import Any

import numpy as np
from labware_interfaces.msg import ErrorCodes

from lab_description.station_placement import approach_heights
from lab_description.world import World
from tiago_description import transforms as tf
from tiago_description.kinematics import CAMERA_FRAME, RobotKinematics
from tiago_description.motion_library import HotelGrasp
from tiago_skills.base_alignment import align_base, search_marker, working_pose
from tiago_skills.behaviours import (
    TOOL_SPEED_FREE,
    TOOL_SPEED_INTO_POCKET,
    RobotBehaviours,
)
from tiago_skills.bench_exit import BenchExit
from tiago_skills.bench_route import BenchRoute, held_plate_box, largest_labware
from tiago_skills.gaze import marker_and_held_plate
from tiago_skills.goal_run import ActionAbort, GoalRun
from tiago_skills.grasp_twins import FLIP_ABOUT_APPROACH
from tiago_skills.joint_commands import move_joints
from tiago_skills.marker_sighting import MarkerSighting, pose_msg, same_place
from tiago_skills.nest_looks import NestLooks
from tiago_skills.perception.aruco import detect_marker
from tiago_skills.pick_correction import NEST_EMPTY
from tiago_skills.place_correction import LOOK_AGAIN, place_shift
from tiago_skills.reachable import first_reachable, put_twin

log = logging.getLogger(__name__)

TARGETS = ("site_approach", "site", "work_pose", "inspect")
LINE_ONLY_RADIUS_M = 0.03  # a tool this near the column above the site moves only in straight lines


class MarkerMotionBehaviour:
    """Execute function of /marker_motion."""

    def __init__(self, world: World, behaviours: RobotBehaviours, grasp: HotelGrasp) -> None:
        self.world = world
        self.behaviours = behaviours
        self.grasp = grasp
        self.route = BenchRoute(behaviours)
        self.held_plate = held_plate_box(list(world.labware_types.values()), grasp)
        self.largest_labware = largest_labware(list(world.labware_types.values()))
        self.exit = BenchExit(self.route, self.held_plate, self.largest_labware, self._cached)
        behaviours.bench_exit = self.exit  # the arm's way back off the bench (Tuck, a put into the hotel)
        self.kinematics = RobotKinematics()
        self._lock = threading.Lock()
        self.last_sighting: MarkerSighting | None = None
        self.nests = NestLooks(world, self.kinematics, self._lock)

    def look(self, run: GoalRun, station_name: str) -> MarkerSighting:
        """Image + joints at one instant, marker detection, marker pose in base_footprint."""
        station = self.world.station(station_name)

        run.feedback(max(run.progress, 0.05), "looking", 0.0, force=True)  # progress never goes back
        frame = run.read(lambda hardware: hardware.capture_head_camera())
        observation = detect_marker(
            frame.rgb, frame.intrinsics, station.marker_id, station.marker_size, frame.depth
        )
        if observation is None:
            raise ActionAbort(ErrorCodes.MARKER_NOT_FOUND, f"marker not found: {station.marker_id}")
        with self._lock:
            T_base_optical = self.kinematics.forward(frame.joints, CAMERA_FRAME)
        sighting = MarkerSighting(
            station_name,
            T_base_optical @ observation.T_optical_marker,
            tuple(frame.odometry),
            observation.reprojection_error_px,
            dict(frame.joints),
            frame.intrinsics,
        )
        log.info(
            "marker %d of %s at %s in base, quaternion %s (reprojection %.2f px)",
            station.marker_id, station_name, np.round(sighting.T_base_marker[:3, 3], 4),
            np.round(tf.matrix_to_quat(sighting.T_base_marker[:3, :3]), 5), observation.reprojection_error_px,
        )  # fmt: skip
        self.last_sighting = sighting
        return sighting

    def _cached(self, run: GoalRun, station_name: str) -> MarkerSighting | None:
        sighting = self.last_sighting
        if sighting is None or sighting.station != station_name:
            return None
        odometry = run.read(lambda hardware: tuple(hardware.odometry()))
        return sighting if same_place(sighting.odometry, odometry) else None

    def _sighting_here(self, run: GoalRun, station: Any) -> MarkerSighting:
        """The marker's sighting from where the base stands: the cached one, else a search from
        where localisation puts the base."""
        sighting = self._cached(run, station.name)
        if sighting is not None:
            return sighting
        believed = run.read(lambda hardware: tuple(hardware.pose_estimate()))
        expected = tf.invert(tf.from_planar(*believed)) @ station.T_world_marker()
        return search_marker(
            run, self.kinematics, expected[:3, 3], lambda r: self.look(r, station.name), None
        )

    def inspect(self, run: GoalRun, station: Any, sub_position: int) -> dict:
        """Whether a plate lies in the nest, from the depth image (`NestLooks.inspect`)."""
        return self.nests.inspect(run, station, sub_position, self._sighting_here(run, station))

    def _centred_on_plate(
        self,
        run: GoalRun,
        arm: str,
        site_seen: Callable[[MarkerSighting], np.ndarray],
        sighting: MarkerSighting,
    ) -> tuple[np.ndarray, MarkerSighting]:
        """The site (``site_seen`` of a marker sighting) moved by the shift that centres the held
        plate on it (as it is without a measurement), and the sighting it was taken with. Taken from
        where the tool stands now, above the nest after the approach. When the head has moved since
        the marker's sighting or the plate is not seen whole (an end out of the image: random layouts
        191031, 211038), the head is turned to frame the marker and the plate's outline together
        (`gaze`), and both are seen again with that one gaze. Where they do not fit in one image, or
        the marker is lost from it, the plate is framed alone and measured against the nest of the
        sighting so far (random layout 218178: a marker 0.5 m beside the nest)."""
        T_base_site = site_seen(sighting)
        shift, why = self._shift(run, arm, T_base_site, sighting)
        if shift is None and why in LOOK_AGAIN:
            joints = run.read(lambda hardware: dict(hardware.joint_positions()))
            tool = self.behaviours.planning.tool_pose(arm, joints)[:3, 3]
            aim, fits = marker_and_held_plate(
                self.kinematics, joints, sighting, self.world, T_base_site, tool
            )
            if not fits:
                log.info("marker and held plate do not fit in one view (%s): framing the plate alone", why)
                return self._plate_alone(run, arm, T_base_site, sighting, tool), sighting
            log.info("looking again with marker and held plate in one view (%s)", why)
            run.follow(move_joints(aim), span=(0.0, 0.1))
            try:
                seen = self.look(run, sighting.station)
            except ActionAbort as lost:
                if lost.code != ErrorCodes.MARKER_NOT_FOUND:
                    raise
                log.info("%s from the new gaze: framing the held plate alone", lost.message)
                return self._plate_alone(run, arm, T_base_site, sighting, tool), sighting
            sighting, T_base_site = seen, site_seen(seen)
            shift, why = self._shift(run, arm, T_base_site, sighting)
        return (T_base_site if shift is None else T_base_site @ tf.from_planar(*shift)), sighting

    def _plate_alone(
        self, run: GoalRun, arm: str, T_base_site: np.ndarray, sighting: MarkerSighting, tool: np.ndarray
    ) -> np.ndarray:
        """The site moved by the shift the held plate measured in a view of its own calls for (as it is
        when the plate is not measured): the nest from `sighting`, the plate from the new image; the
        camera's error between the two head aims is not cancelled (`gaze`)."""
        joints = run.read(lambda hardware: dict(hardware.joint_positions()))
        aim, fits = marker_and_held_plate(
            self.kinematics, joints, sighting, self.world, T_base_site, tool, with_marker=False
        )
        run.follow(move_joints(aim), span=(0.0, 0.1))
        now = run.read(lambda hardware: dict(hardware.joint_positions()))
        shift, why = self._shift(run, arm, T_base_site, dataclasses.replace(sighting, joints=now))
        if shift is None:
            log.info("held plate not measured alone either (%s): placing where the marker says", why)
            return T_base_site
        whole = "" if fits else " (its outline beyond the image)"
        log.info("held plate measured in a view of its own%s", whole)
        return T_base_site @ tf.from_planar(*shift)

    def _shift(
        self, run: GoalRun, arm: str, T_base_site: np.ndarray, sighting: MarkerSighting
    ) -> tuple[tf.Planar | None, str]:
        def capture() -> tuple:
            frame = run.read(lambda hardware: hardware.capture_head_camera())
            return frame.depth, frame.intrinsics, dict(frame.joints)

        def forward(joints: dict[str, float], frame: str) -> np.ndarray:
            with self._lock:
                return self.kinematics.forward(joints, frame)

        return place_shift(
            capture,
            forward,
            T_base_site,
            arm,
            CAMERA_FRAME,
            sighting.joints,
            self.world.labware_types.values(),
            self.grasp.grasp_height_m,
        )

    def _approach_heights(self, station: Any) -> list[float]:
        """The station's approach height, then the lower ones down to the least that keeps a held plate
        over a neighbour's tallest labware (station_placement.approach_heights), highest first."""
        tallest = max((t.height for t in self.world.labware_types.values()), default=0.0)
        lower = [h for h in approach_heights(tallest) if h < station.approach_height - 1e-9]
        return [station.approach_height, *lower]

    def _in_the_column(self, run: GoalRun, arm: str, T_base_target: np.ndarray) -> bool:
        """Whether the tool is in the column above the nest (in the nest, or just out of it): from
        there it only rises or sinks straight; from anywhere else it comes by the first clear way
        (bench_route), which may leave the line: from the arm-to-bench pose to the far nest of a 4-nest
        row the line left the arm's reach at waypoint 12 of 34, though the nest itself is reachable."""
        joints = run.read(lambda hardware: dict(hardware.joint_positions()))
        tool = self.behaviours.planning.tool_pose(arm, joints)[:3, 3]
        return float(np.hypot(*(tool[:2] - T_base_target[:2, 3]))) <= LINE_ONLY_RADIUS_M

    def _straight_in_the_column(
        self, run: GoalRun, arm: str, grasps: list[np.ndarray], speed: float, span: tuple[float, float]
    ) -> None:
        """Straight up or down the column above the nest to the first of `grasps` (the approach heights
        that reach, highest first) whose line the arm can follow, the tool turned as it stands (the twin
        it is in). Why: after a release the empty gripper's twin is free, and the one of least joint
        travel at the approach was the other: the line up turned the wrist half round and passed a flip
        the arm could not follow, with the torso either, 80 mm over a nest 0.88 m high (random layout
        219071); a lower approach is tried before giving up."""
        joints = run.read(lambda hardware: dict(hardware.joint_positions()))
        now = self.behaviours.planning.tool_pose(arm, joints)[:3, :3]
        for number, T_base_grasp in enumerate(grasps):
            flipped = T_base_grasp @ FLIP_ABOUT_APPROACH
            turned = np.linalg.norm(flipped[:3, :3] - now) < np.linalg.norm(T_base_grasp[:3, :3] - now)
            try:
                self.behaviours.straight_move(run, arm, flipped if turned else T_base_grasp, speed, span)
                self.behaviours.grasp_flipped[arm] = bool(turned)
                return
            except ActionAbort as abort:
                if abort.code != ErrorCodes.IK_FAILED or number == len(grasps) - 1:
                    raise
                log.info("no straight line up the column (%s): trying a lower approach", abort.message)

    def __call__(self, run: GoalRun, goal: Any) -> dict:
        arm = self.behaviours.arm_of(goal.arm)
        try:
            station = self.world.station(goal.station)
        except KeyError:
            names = ", ".join(s.name for s in self.world.stations)
            raise ActionAbort(
                ErrorCodes.UNKNOWN_STATION, f"unknown station {goal.station!r}: known are {names}"
            ) from None
        if goal.target not in TARGETS:
            raise ActionAbort(
                ErrorCodes.BAD_GOAL, f"unknown target {goal.target!r}: use {' or '.join(TARGETS)}"
            )
        sub_position = int(goal.sub_position)
        if not 1 <= sub_position <= station.sub_positions:
            raise ActionAbort(
                ErrorCodes.BAD_GOAL,
                f"station {station.name} has sub-positions 1..{station.sub_positions}, not {sub_position}",
            )
        if goal.target == "work_pose":  # final approach of the base, guided by the marker
            bench = self.behaviours.motions.frames_for("Benchtop", arm)[0]
            posture = {name: value for name, value in bench.items() if not name.startswith("arm_")}
            T_world_work = working_pose(station, sub_position, arm)
            sighting = align_base(
                run, station, self.kinematics, lambda r: self.look(r, station.name), posture, T_world_work
            )
            if not self.behaviours.holding.get(arm, False):
                self.behaviours.twin_wanted[arm] = None  # a pick takes the twin of least travel
                if self.nests.find_plate(run, station, sub_position, sighting) == NEST_EMPTY:  # a put
                    site = self.nests.nest_seen(station, sub_position, sighting)
                    seed = run.read(lambda hardware: dict(hardware.joint_positions()))
                    heights = self._approach_heights(station)
                    wanted = put_twin(self.behaviours, arm, site, heights, self.grasp, seed)
                    self.behaviours.twin_wanted[arm] = wanted
            return {"marker_in_base": pose_msg(sighting.T_base_marker)}
        if goal.target == "inspect":
            return self.inspect(run, station, sub_position)
        sighting = self._cached(run, station.name)
        if sighting is None:
            sighting = self.look(run, station.name)
        self.exit.over(arm, station, sub_position)
        marker_in_base = pose_msg(sighting.T_base_marker)
        seed = run.read(lambda hardware: dict(hardware.joint_positions()))
        # Nests sit on level benches and the base stands on the floor, so the nest frame is levelled:
        # a marker glued 1.4 deg askew in its plane tilted the perceived nest by as much, and together
        # with the height it shifts put a finger tip into the bench ("nothing between the fingers").
        # Heading and position still come from the marker.
        # The marker's tilt comes from the level bench, not the image (perception.site_frames.upright_marker).
        # The height is the bench's (world file), not the sighting's (perception.site_frames.at_height).

        plate = self.nests.plates_seen.get(
            (station.name, sub_position)
        )  # a pick: the grasp goes to the plate
        on_plate = (
            tf.from_planar(*plate[1]) if plate and same_place(plate[0], sighting.odometry) else np.eye(4)
        )

        def site_seen(seen: MarkerSighting, above_m: float = 0.0) -> np.ndarray:
            """The nest (or the point `above_m` over it) in base_footprint, from a marker sighting."""
            return self.nests.nest_seen(station, sub_position, seen, above_m) @ on_plate

        releasing = goal.target == "site" and self.behaviours.holding.get(arm, False)
        grasp_in_site = self.grasp.T_slot_grasp(approach=False, releasing=releasing)
        if goal.target == "site":
            as_marked = site_seen(sighting)
            places = [as_marked]
            if releasing:  # where the plate hangs, seen with the nest's marker: shift the tool to centre it
                measured, sighting = self._centred_on_plate(run, arm, site_seen, sighting)
                marker_in_base = pose_msg(sighting.T_base_marker)
                places = [measured] if measured is as_marked else [measured, as_marked]
            grasps = [place @ grasp_in_site for place in places]
            T_base_target, index = first_reachable(self.behaviours, arm, grasps, seed)
            if index:
                log.warning("the measured place is out of the %s arm's reach: placing as marked", arm)
        else:
            heights = self._approach_heights(station)
            grasps = [site_seen(sighting, height) @ grasp_in_site for height in heights]
            T_base_target, index = first_reachable(self.behaviours, arm, grasps, seed)
            if index:
                log.warning(
                    "the %s arm does not reach %.0f mm above nest %d of %s: approaching at %.0f mm",
                    arm, 1000 * heights[0], sub_position, station.name, 1000 * heights[index],
                )  # fmt: skip
        in_nest = goal.target == "site"  # slow only where the plate enters or leaves the nest
        speed = TOOL_SPEED_INTO_POCKET if in_nest else TOOL_SPEED_FREE
        # From the hotel (PutLabware): straight up to the carry height, then straight to the bench.
        # The sighting taken at the end of the final approach stays valid: the base has not moved.
        first = 0.1 if in_nest else max(0.1, self.behaviours.leave_hotel(run, arm))
        try:
            if in_nest:
                self.behaviours.into_pocket(run, arm, T_base_target, (first, 1.0))
                return {"marker_in_base": marker_in_base}
            first = self.behaviours.rise_before_bench(run, arm, T_base_target, first)
            if self._in_the_column(run, arm, T_base_target):
                self._straight_in_the_column(run, arm, grasps[index:], speed, (first, 1.0))
                return {"marker_in_base": marker_in_base}
            holding = self.behaviours.holding.get(arm, False)
            # An empty gripper may come down as either twin: the other one may have a clear way.
            targets = [T_base_target] if holding else [T_base_target, T_base_target @ FLIP_ABOUT_APPROACH]
            boxes = self.exit.boxes(station, sighting, sub_position, holding)
            reached = self.route.move(run, arm, targets, speed, (first, 1.0), boxes, self.exit.held(arm))
            if reached:
                self.behaviours.grasp_flipped[arm] = not self.behaviours.grasp_flipped.get(arm, False)
        except ActionAbort as abort:
            abort.extra = {"marker_in_base": marker_in_base}
            raise
        return {"marker_in_base": marker_in_base}
