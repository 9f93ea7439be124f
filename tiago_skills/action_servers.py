"""The robot's action servers: navigate, dock, undock, play motion, marker motion, gripper.

Every server accepts a goal at once and decides in its execute callback: an unknown POI,
station, slot or motion ends the goal immediately as aborted with a code and a reason (so the
client reads why); a second motion while one runs ends with BUSY. The work itself is a sequence
of steps on the hardware port (see goal_run.GoalRun). Lives on: rclpy executor threads.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from labware_interfaces.action import Dock, Gripper, MarkerMotion, NavigateToPoi, PlayMotion, Undock
from labware_interfaces.msg import ErrorCodes, RobotState
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from robot_port.hardware import RobotHardware
from tiago_skills.goal_run import ActionAbort, GoalRun, MotionSlot

log = logging.getLogger(__name__)

# Codes after which the robot reports the error state until the next goal succeeds.
FAULT_CODES = frozenset(
    {
        ErrorCodes.NAVIGATION_FAILED,
        ErrorCodes.IK_FAILED,
        ErrorCodes.MOTION_FAILED,
        ErrorCodes.GRASP_FAILED,
        ErrorCodes.PLATE_SLIPPED,
        ErrorCodes.PLACE_FAILED,
        ErrorCodes.COLLISION,
        ErrorCodes.INTERNAL,
    }
)

# Execute functions receive the goal's GoalRun and the goal request; they return a dict of
# extra result fields (beyond success/error_code/message) or raise ActionAbort.
ExecuteFn = Callable[[GoalRun, Any], dict]


# The base's odometry and its pose in the map as believed (x, y, yaw each), and every joint's
# reading, at one instant.
Readings = tuple[tuple[float, ...], tuple[float, ...], dict[str, float]]
MOVED_BY = 1e-4  # rad or m: a joint that changed less than this over a goal is left out of its line


def describe_motion(before: Readings | None, after: Readings | None) -> str:
    """The base's poses and the joints that changed, at a goal's start and end, as one log line.

    Why: a step's least possible time under the robot's limits depends on what it moved, not on
    its name; this line is the record of that (tiago_sim.measuring.time_budget reads it)."""
    if before is None or after is None:
        return "no readings"
    (odometry0, map0, joints0), (odometry1, map1, joints1) = before, after
    moved = [
        f"{name} {joints0[name]:.4f}>{joints1[name]:.4f}"
        for name in sorted(joints0.keys() & joints1.keys())
        if abs(joints1[name] - joints0[name]) >= MOVED_BY
    ]
    odometry, believed = (
        " -> ".join("({:.4f}, {:.4f}, {:.4f})".format(*pose) for pose in poses)
        for poses in ((odometry0, odometry1), (map0, map1))
    )
    return f"odometry {odometry}; map {believed}; joints {', '.join(moved) or 'none'}"


class RobotActivity:
    """What the robot is doing, for /robot_state (written by goals, read by the publisher).

    Also what it did between two reads: a goal shorter than the publisher's period (a 2 s drive
    at 50 times real time lasts 40 ms) would otherwise never show as navigating, and a SiLA
    client following RobotState would miss the state altogether."""

    def __init__(self) -> None:
        self.state = ""  # "" (derive idle/docked from sensors), navigating, manipulating, error
        self.detail = ""
        self.last_error = ""
        self._lock = threading.Lock()
        self._begun: list[tuple[str, str]] = []  # since the last snapshot

    def begin(self, state: str, detail: str) -> None:
        with self._lock:
            self.state, self.detail = state, detail
            self._begun.append((state, detail))

    def clear(self) -> None:
        """Nothing running, no error standing (after a lab reset)."""
        with self._lock:
            self.state, self.detail, self.last_error, self._begun = "", "", "", []

    def signature(self) -> tuple[str, str, str, int]:
        """What the next report would show, without taking the goals begun since the last one (for
        a publisher to tell news from a robot standing still)."""
        with self._lock:
            return (self.state, self.detail, self.last_error, len(self._begun))

    def snapshot(self) -> ActivityReport:
        """The current (state or "", detail), and the activities begun and ended since the last call."""
        with self._lock:
            begun, self._begun = self._begun, []
            if self.state:
                return ActivityReport(self.state, self.detail, tuple(begun[:-1]))
            current = (RobotState.STATE_ERROR, self.last_error) if self.last_error else ("", self.detail)
            return ActivityReport(*current, tuple(begun))


@dataclass(frozen=True)
class ActivityReport:
    state: str  # "" when no goal runs and no fault stands: idle or docked, as the sensors say
    detail: str
    passed: tuple[tuple[str, str], ...] = ()  # (state, detail) of goals that began and ended unseen


class RobotActionServers:
    """Creates the six action servers on `node`; behaviour comes from the execute functions."""

    def __init__(
        self,
        node: Node,
        hardware: RobotHardware,
        *,
        navigate: ExecuteFn,
        dock: ExecuteFn,
        undock: ExecuteFn,
        play_motion: ExecuteFn,
        marker_motion: ExecuteFn,
        gripper: ExecuteFn,
        feedback_hz: float = 5.0,
        motion_time: Callable[[], float] = lambda: 0.0,
    ) -> None:
        self.node = node
        self.hardware = hardware
        # Robot time with a command running, for the goal log line, where the hardware counts it
        # (the simulator does); 0 elsewhere.
        self.motion_time = motion_time
        self.slot = MotionSlot()
        self.activity = RobotActivity()
        self.feedback_hz = feedback_hz
        group = ReentrantCallbackGroup()
        specs = [
            ("/navigate_to_poi", NavigateToPoi, navigate, RobotState.STATE_NAVIGATING),
            ("/dock", Dock, dock, RobotState.STATE_NAVIGATING),
            ("/undock", Undock, undock, RobotState.STATE_NAVIGATING),
            ("/play_motion", PlayMotion, play_motion, RobotState.STATE_MANIPULATING),
            ("/marker_motion", MarkerMotion, marker_motion, RobotState.STATE_MANIPULATING),
            ("/gripper", Gripper, gripper, RobotState.STATE_MANIPULATING),
        ]
        self.servers = [
            ActionServer(
                node,
                action_type,
                name,
                self._execute_callback(name, action_type, execute, state),
                callback_group=group,
                goal_callback=lambda _goal: GoalResponse.ACCEPT,
                cancel_callback=lambda _handle: CancelResponse.ACCEPT,
            )
            for name, action_type, execute, state in specs
        ]

    def _execute_callback(self, name: str, action_type: Any, execute: ExecuteFn, state: str) -> Callable:
        def callback(goal_handle: Any) -> Any:
            run = GoalRun(goal_handle, action_type.Feedback, self.hardware, feedback_hz=self.feedback_hz)
            result = action_type.Result()
            acquired = False
            sim_started, busy_started = self._now(), self.motion_time()
            before = self._readings()
            try:
                self.slot.acquire(name)
                acquired = True
                self.activity.begin(state, name.lstrip("/"))
                run.feedback(0.0, "starting", 0.0, force=True)
                extra = execute(run, goal_handle.request) or {}
                for field_name, value in extra.items():
                    setattr(result, field_name, value)
                result.success, result.error_code, result.message = True, "", "done"
                self.activity.last_error = ""
                self.activity.detail = f"{name.lstrip('/')} done"
                run.feedback(1.0, "done", 0.0, force=True)
                goal_handle.succeed()
            except ActionAbort as abort:
                self._fill_failure(result, abort.code, abort.message, getattr(abort, "extra", None))
                self._finish_failed(goal_handle, abort.code, name, abort.message, acquired)
            except Exception as error:  # noqa: BLE001 - every goal ends with a result
                log.exception("%s failed", name)
                self._fill_failure(result, ErrorCodes.INTERNAL, f"internal error: {error}", None)
                self._finish_failed(goal_handle, ErrorCodes.INTERNAL, name, str(error), acquired)
            finally:
                if acquired:
                    self.activity.state = ""
                    self.slot.release()
                # what the goal moved, read through the port (tiago_sim.measuring.time_budget's minima)
                log.info("%s moved: %s", name, describe_motion(before, self._readings()))
                # one line per goal with its simulated span (tiago_sim.measuring.benchmark times phases by it)
                log.info(
                    "%s %s: sim %.3f .. %.3f s, %.3f s of it with no motion running",
                    name, result.error_code or "done", sim_started, ended := self._now(),
                    ended - sim_started - (self.motion_time() - busy_started),
                )  # fmt: skip
            return result

        return callback

    def _now(self) -> float:
        try:
            return float(self.hardware.now())
        except Exception:  # noqa: BLE001 - a log line's figure, never a goal's end
            return float("nan")

    def _readings(self) -> Readings | None:
        try:
            hardware = self.hardware
            return (
                tuple(hardware.odometry()),
                tuple(hardware.pose_estimate()),
                dict(hardware.joint_positions()),
            )
        except Exception:  # noqa: BLE001 - a log line's figures, never a goal's end
            return None

    @staticmethod
    def _fill_failure(result: Any, code: str, message: str, extra: dict | None) -> None:
        result.success, result.error_code, result.message = False, code, message
        for field_name, value in (extra or {}).items():
            setattr(result, field_name, value)

    def _finish_failed(self, goal_handle: Any, code: str, name: str, message: str, acquired: bool) -> None:
        if acquired:
            self.activity.detail = f"{name.lstrip('/')}: {code}: {message}"
            if code in FAULT_CODES:
                self.activity.last_error = f"{name.lstrip('/')}: {code}: {message}"
        log.info("%s ended: %s %s", name, code, message)
        if code == ErrorCodes.CANCELED and goal_handle.is_cancel_requested:
            goal_handle.canceled()
        else:
            goal_handle.abort()
