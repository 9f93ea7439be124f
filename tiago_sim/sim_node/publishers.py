"""Topics of the sim node: /clock, /mobile_base_controller/odom, /joint_states, /robot_state,
/station_states, the head camera's (camera_topics) and localisation's (/scan_raw, /amcl_pose,
/map_to_odom: localisation_topics).

A wall-clock timer (executor thread) takes one snapshot of the robot's own sensors from the sim
thread and publishes it; nothing here touches PyBullet directly. /robot_state goes out when it
changes and at 2 Hz; /station_states when a nest or the robot state changes and at 2 Hz; the head
camera only while someone subscribes.
Lives on: the rclpy executor threads of the sim node.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from concurrent.futures import TimeoutError as FutureTimeout
from dataclasses import dataclass, field, replace
from typing import Any

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Pose2D
from labware_interfaces.msg import HotelSlot, NestState, RobotState, StationStates
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState

from labware_model.readings import HotelSlotReading, NestReading
from robot_port.tiago_interfaces import ODOMETRY
from tiago_description.transforms import wrap_angle
from tiago_sim.sim_node.camera_topics import CameraTopics
from tiago_sim.sim_node.localisation import LocalisationLoop
from tiago_sim.sim_node.localisation_topics import LocalisationTopics, LocalisationView, stamp_of
from tiago_sim.sim_node.sim_thread import SimThread

log = logging.getLogger(__name__)

# The robot state and station states go out at least this often (s), news or not: a reader's
# clock (SimulatedLabController.SimulatedTime reads the last /robot_state's stamp) is never staler.
SLOW_PERIOD_S = 0.5
SNAPSHOT_WAIT_S = 0.03  # s a state tick waits for the sim thread's snapshot (ticks are 50 ms apart)


@dataclass(frozen=True)
class RobotSnapshot:
    """What the robot's own sensors report at one instant of simulated time."""

    sim_time: float
    odometry: tuple[float, float, float]
    joint_positions: dict[str, float]
    docked: bool
    hotel: list[HotelSlotReading]
    held_labware_id: str
    holding: bool = False  # a plate between the pads (presence), read or not
    nests: list[NestReading] = field(default_factory=list)
    true_base_pose: tuple[float, float, float] | None = None  # simulator truth, for measurement only
    pose_estimate: tuple[float, float, float] | None = None  # localised; None: odometry stands for it
    localisation: LocalisationView = LocalisationView(None, None)
    activity: tuple[str, str] = ("", "")  # (state or "", detail) of the action servers at that instant
    passed_activities: tuple[tuple[str, str], ...] = ()  # goals begun and ended since the last snapshot


def take_snapshot(sim: Any) -> RobotSnapshot:
    """Read the sensors the lab has (runs on the sim thread): the world's `sensors` say which of
    the lab-added ones exist. Without hotel sensors the hotel is not reported at all; without
    label readers no id is. The nests' sensors are the instruments' own: they are reported
    whatever the robot's checks read (the station servers follow them)."""
    sensors = sim.world.sensors
    held = ""
    if sensors.label_readers:
        for arm in ("right", "left"):
            held = held or sim.held_labware(arm)
    holding = any(sim.gripper_holds(arm) for arm in ("right", "left"))
    hotel = list(sim.hotel_readings()) if sensors.hotel else []
    nests = list(sim.nest_readings())
    if not sensors.label_readers:
        hotel = [replace(r, labware_id="", labware_type="") for r in hotel]
        nests = [replace(r, labware_id="") for r in nests]
    return RobotSnapshot(
        sim_time=float(sim.sim_time),
        odometry=tuple(float(v) for v in sim.odometry()),
        joint_positions=dict(sim.joint_positions()),
        docked=bool(sim.is_docked()),
        hotel=hotel,
        held_labware_id=held,
        holding=holding,
        nests=nests,
        true_base_pose=_true_base_pose(sim),
        pose_estimate=tuple(float(v) for v in sim.pose_estimate()),
    )


def _true_base_pose(sim: Any) -> tuple[float, float, float] | None:
    """Ground-truth floor pose of the base, if the simulation exposes it (benchmarks only)."""
    robot = getattr(sim, "robot", None)
    if robot is None or not hasattr(robot, "base_pose"):
        return None
    T_world_base = robot.base_pose()
    return (
        float(T_world_base[0, 3]),
        float(T_world_base[1, 3]),
        math.atan2(T_world_base[1, 0], T_world_base[0, 0]),
    )


def _occupied_nests(nests: tuple[NestReading, ...]) -> str:
    """'station_a:1=plate_001, ...' for the log: which nests hold which plate."""
    return ", ".join(
        f"{reading.nest.station}:{reading.nest.sub_position}={reading.labware_id}"
        for reading in nests
        if reading.occupied
    )


def poi_at(
    pose: tuple[float, float, float],
    pois: dict[str, tuple[float, float, float]],
    position_tolerance_m: float,
    yaw_tolerance_rad: float,
) -> str:
    """Name of the POI the base stands at (within tolerance), or ""."""
    x, y, yaw = pose
    best, best_distance = "", position_tolerance_m
    for name, (px, py, pyaw) in pois.items():
        distance = math.hypot(px - x, py - y)
        if distance <= best_distance and abs(wrap_angle(pyaw - yaw)) <= yaw_tolerance_rad:
            best, best_distance = name, distance
    return best


class StatePublishers:
    """Publishes the sim node's topics from periodic sensor snapshots."""

    def __init__(
        self,
        node: Node,
        sim_thread: SimThread,
        *,
        pois: Callable[[], dict[str, tuple[float, float, float]]],
        activity: Callable[[], Any],
        localisation: LocalisationLoop | None = None,
        activity_signature: Callable[[], tuple] | None = None,
        rate_hz: float = 20.0,
        idle_rate_hz: float = 5.0,
    ) -> None:
        self.node = node
        self.sim_thread = sim_thread
        self.pois = pois
        self.activity = activity  # -> action_servers.ActivityReport
        # While no goal runs and none began or ended since the last report, reports go out at
        # idle_rate_hz: a robot standing still changes nothing a 20 Hz report would show, and the
        # ticks (a snapshot on the sim thread, six messages built and read by the bridge and the
        # sequencer) cost about 5 % of a campaign trial's CPU between goals (paired runs, README
        # "Campaign speed"). A goal's start or end is reported at the next 20 Hz tick.
        self.activity_signature = activity_signature
        self.idle_period_s = 1.0 / idle_rate_hz
        self._reported_signature: tuple | None = None
        self._reported_at = -1e9
        self.localisation = localisation
        self.localisation_topics = LocalisationTopics(node)
        self.latest: RobotSnapshot | None = None
        # Wide enough to cover the marker-guided final approach (the base works ~12 cm closer to
        # the table than the station's POI) plus navigation error; POIs lie metres apart.
        self.poi_tolerance_m = 0.25
        self.poi_yaw_tolerance_rad = 0.15
        reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self.clock_pub = node.create_publisher(Clock, "/clock", reliable)
        self.odom_pub = node.create_publisher(Odometry, ODOMETRY, reliable)
        self.joint_pub = node.create_publisher(JointState, "/joint_states", reliable)
        self.robot_state_pub = node.create_publisher(RobotState, "/robot_state", reliable)
        self.station_pub = node.create_publisher(StationStates, "/station_states", reliable)
        # Simulator truth, like Gazebo's ground-truth plugins: for benchmarks, never for the robot.
        self.truth_pub = node.create_publisher(Pose2D, "/ground_truth/base_pose", reliable)
        self.camera = CameraTopics(node, sim_thread)
        self._last_robot_key: tuple | None = None
        self._last_nests: tuple | None = None
        self._last_slow_publish = 0.0
        self._pending: Any = None
        self._previous_odometry: tuple[float, tuple[float, float, float]] | None = None
        node.create_timer(1.0 / rate_hz, self._tick)

    # -- sensors -> topics ---------------------------------------------------------------
    def _tick(self) -> None:
        """Take a snapshot and publish it in the same tick when the sim thread answers within
        SNAPSHOT_WAIT_S (it answers between batches of steps, a few ms apart); else at a later tick.
        Why not publish it one tick later: the sequencer checks each step's effect on a report read
        after the step, and that wait was one tick (50 ms) longer, nine times a transfer."""
        if self._pending is None:
            if self._standing_still():
                return
            if self.localisation is not None:  # a plain flag the sim thread reads
                self.localisation.scans_wanted = self.localisation_topics.scans_wanted()
            self._pending = self.sim_thread.call(self._snapshot_with_activity)
        try:
            snapshot = self._pending.result(timeout=SNAPSHOT_WAIT_S)
        except FutureTimeout:
            return  # the sim thread is still answering: the next tick publishes it
        except Exception:  # noqa: BLE001 - the simulation is stopping; the next tick asks again
            self._pending = None
            return
        self._pending = None
        self._publish(snapshot)

    def _standing_still(self) -> bool:
        """No goal ran at the last report, none began or ended since, nothing moves (a command from
        the robot's own interfaces runs no goal), and it is less than an idle period old."""
        if self.activity_signature is None or self.sim_thread.in_motion:
            return False
        signature = self.activity_signature()
        if signature[0] or signature != self._reported_signature:
            return False
        now = time.monotonic()
        if now - self._last_slow_publish >= SLOW_PERIOD_S:  # the periodic reports keep their beat
            return False
        return now - self._reported_at < self.idle_period_s

    def _snapshot_with_activity(self, sim: Any) -> RobotSnapshot:
        """Sensors and activity read at the same instant (on the sim thread): a state read later
        than the pose said "idle" beside the pose of a base still braking (10 cm off, under load)."""
        report = self.activity()
        if self.activity_signature is not None:  # read with the report: both or neither see a change
            self._reported_signature = self.activity_signature()
        self._reported_at = time.monotonic()
        loop = self.localisation
        view = LocalisationView(None, None)
        if loop is not None:
            view = LocalisationView(loop.latest_scan, loop.latest)
        return replace(
            take_snapshot(sim),
            activity=(report.state, report.detail),
            passed_activities=report.passed,
            localisation=view,
        )

    def _publish(self, snapshot: RobotSnapshot) -> None:
        self.latest = snapshot
        stamp = stamp_of(snapshot.sim_time)
        self.clock_pub.publish(Clock(clock=stamp))
        self._publish_odometry(snapshot, stamp)
        self.localisation_topics.publish(snapshot.localisation)
        joints = JointState()
        joints.header.stamp = stamp
        joints.name = list(snapshot.joint_positions)
        joints.position = [float(v) for v in snapshot.joint_positions.values()]
        self.joint_pub.publish(joints)
        for passed_state, detail in snapshot.passed_activities:  # each state shows, however short
            self.robot_state_pub.publish(self.robot_state(replace(snapshot, activity=(passed_state, detail))))
        state = self.robot_state(snapshot)
        key = (
            state.state,
            state.detail,
            state.current_poi,
            tuple((h.labware_id, h.occupied) for h in state.hotel),
            state.held_labware_id,
            state.holding,
        )
        now = time.monotonic()
        slow_due = now - self._last_slow_publish >= SLOW_PERIOD_S
        robot_news = key != self._last_robot_key
        if robot_news or slow_due:
            self.robot_state_pub.publish(state)
            self._last_robot_key = key
        # A nest that fills or empties is news too: the sequencer checks the source nest from this
        # topic, and a GetLabware sent right after a place must not read the nest as still empty.
        # So is a robot goal's end (the robot state changed): the sequencer then checks the nest
        # a place released into, from a report taken after the release, without waiting 0.5 s.
        nests = tuple(snapshot.nests)
        if nests != self._last_nests or slow_due or robot_news:
            self.station_pub.publish(self.station_states(snapshot))
            if nests != self._last_nests:
                log.info("nests at sim %.3f s: %s", snapshot.sim_time, _occupied_nests(nests))
            self._last_nests = nests
        if slow_due:
            self._last_slow_publish = now
            if snapshot.true_base_pose is not None:
                x, y, yaw = snapshot.true_base_pose
                self.truth_pub.publish(Pose2D(x=x, y=y, theta=yaw))

    def _publish_odometry(self, snapshot: RobotSnapshot, stamp: Time) -> None:
        x, y, yaw = snapshot.odometry
        odom = Odometry()
        odom.header.stamp = stamp
        odom.header.frame_id = "odom"
        odom.child_frame_id = "base_footprint"
        odom.pose.pose.position.x, odom.pose.pose.position.y = x, y
        odom.pose.pose.orientation.z = math.sin(yaw / 2.0)
        odom.pose.pose.orientation.w = math.cos(yaw / 2.0)
        if self._previous_odometry is not None:
            previous_time, (px, py, pyaw) = self._previous_odometry
            dt = snapshot.sim_time - previous_time
            if dt > 1e-6:
                vx_world, vy_world = (x - px) / dt, (y - py) / dt
                odom.twist.twist.linear.x = math.cos(yaw) * vx_world + math.sin(yaw) * vy_world
                odom.twist.twist.linear.y = -math.sin(yaw) * vx_world + math.cos(yaw) * vy_world
                odom.twist.twist.angular.z = wrap_angle(yaw - pyaw) / dt
        self._previous_odometry = (snapshot.sim_time, snapshot.odometry)
        self.odom_pub.publish(odom)

    def robot_state(self, snapshot: RobotSnapshot) -> RobotState:
        activity, detail = snapshot.activity
        message = RobotState()
        message.stamp = stamp_of(snapshot.sim_time)
        if activity:
            message.state = activity
        elif snapshot.docked:
            message.state = RobotState.STATE_DOCKED
        else:
            message.state = RobotState.STATE_IDLE
        message.detail = detail
        # where the robot believes it stands: the localised pose (odometry only if there is none)
        believed = snapshot.pose_estimate or snapshot.odometry
        message.current_poi = poi_at(believed, self.pois(), self.poi_tolerance_m, self.poi_yaw_tolerance_rad)
        x, y, yaw = believed
        message.base_pose = Pose2D(x=x, y=y, theta=yaw)
        message.hotel = [
            HotelSlot(
                index=reading.slot.index,
                labware_id=reading.labware_id,
                labware_type=reading.labware_type,
                occupied=reading.occupied,
            )
            for reading in snapshot.hotel
        ]
        message.held_labware_id = snapshot.held_labware_id
        message.holding = snapshot.holding or bool(snapshot.held_labware_id)
        return message

    @staticmethod
    def station_states(snapshot: RobotSnapshot) -> StationStates:
        return StationStates(
            nests=[
                NestState(
                    station=reading.nest.station,
                    sub_position=reading.nest.sub_position,
                    occupied=bool(reading.occupied),
                    labware_id=reading.labware_id,
                )
                for reading in snapshot.nests
            ]
        )
