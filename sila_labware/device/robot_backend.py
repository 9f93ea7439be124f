"""What the device logic needs from a robot below it: the back-end protocols of the controllers.

`RobotController` and `StationController` are the front end (the behaviour behind the SiLA
features); below them sits a back end that reaches a robot. `ros_bridge.robot_link.RobotLink`
is the real one (ROS 2 over DDS, whatever serves the labware_interfaces names: the simulation or
a real TIAGo++); `tests.helpers.fake_robot.FakeRobot` is an in-memory one for millisecond tests.
Both satisfy these protocols structurally; nothing here inherits from them.

Contract common to every method:

- Units are SI: lengths in m, angles in rad, times and timeouts in s. Sub-positions (nests) and
  hotel slots are 1-based, as in the SiLA labware transfer standard.
- Errors are `ros_bridge.errors` types: `BridgeTimeout` when a wait ran out, `BridgeError` (or a
  subclass) when the back end could not do what was asked at all. A robot that answers "no" is
  not an error: it is an unsuccessful `ActionOutcome` on the goal.
- Threads: call from any thread except the one that delivers the back end's answers (for
  `RobotLink` the ROS thread): the waits here block until that thread answers. Listeners and goal
  progress listeners are called on that answering thread and must stay short.
- Goal senders return an `ActionGoal` at once (see ros_bridge.goal_status for its contract:
  wait, cancel, progress, callbacks) and raise `BridgeError` only if the goal could not be sent.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol, runtime_checkable

from labware_model.holders import Nest
from labware_model.readings import NestReading
from ros_bridge.goal_status import ActionGoal
from ros_bridge.progress import GoalProgress
from ros_bridge.workcell import InventorySnapshot, LabwareHandover, RobotStatus

FeedbackListener = Callable[[GoalProgress], None]


@runtime_checkable
class StationBackend(Protocol):
    """The stations' nest sensors, as a station's digital twin reads them."""

    def nest_readings(self, timeout_s: float = 5.0) -> tuple[NestReading, ...]:
        """The latest reading of every nest sensor of every station (waits up to `timeout_s` s
        for a first reading; raises BridgeTimeout if none came)."""
        ...

    def wait_for_nest(self, nest: Nest, occupied: bool, timeout_s: float = 5.0) -> None:
        """Return once the sensor of `nest` reports `occupied` (at once if it already does); raise
        BridgeTimeout after `timeout_s` s."""
        ...


@runtime_checkable
class RobotBackend(StationBackend, Protocol):
    """The methods `RobotController` uses: state, state waits, the inventory, and the robot's five goals."""

    # --- robot state ---

    def robot_status(self, timeout_s: float = 5.0) -> RobotStatus:
        """The latest robot state: state word, base pose (m, rad), hotel and gripper contents.
        Waits up to `timeout_s` s for a first state; raises BridgeTimeout if none came."""
        ...

    def wait_for_robot_status(
        self, predicate: Callable[[RobotStatus], bool], timeout_s: float = 5.0
    ) -> RobotStatus:
        """Return the first robot state (the latest one included) for which `predicate` is true;
        raise BridgeTimeout after `timeout_s` s. `predicate` runs on any thread: keep it pure."""
        ...

    def on_robot_status(self, listener: Callable[[RobotStatus], None]) -> None:
        """Call `listener(status)` on every change of the robot state, on the answering thread."""
        ...

    # --- the robot side's inventory (labware_model.inventory) ---

    def inventory(self, timeout_s: float = 5.0) -> InventorySnapshot:
        """The robot side's latest inventory: every named plate and where its sensors put it.
        Waits up to `timeout_s` s for a first one; raises BridgeTimeout if none came."""
        ...

    def wait_for_inventory(
        self, predicate: Callable[[InventorySnapshot], bool], timeout_s: float = 5.0
    ) -> InventorySnapshot:
        """Return the first inventory (the latest one included) for which `predicate` is true;
        raise BridgeTimeout after `timeout_s` s."""
        ...

    def on_inventory(self, listener: Callable[[InventorySnapshot], None]) -> None:
        """Call `listener(snapshot)` on every change of the inventory, on the answering thread."""
        ...

    # --- goals: each returns its ActionGoal at once ---

    def navigate_to_poi(self, poi: str, on_feedback: FeedbackListener | None = None) -> ActionGoal:
        """Drive the base to the point of interest named `poi` (undocked). An unknown name ends
        the goal with error code UNKNOWN_POI."""
        ...

    def dock(self, on_feedback: FeedbackListener | None = None) -> ActionGoal:
        """Drive onto the charging dock; the robot state then reads "docked"."""
        ...

    def undock(self, on_feedback: FeedbackListener | None = None, then_poi: str = "") -> ActionGoal:
        """Leave the charging dock; the robot state then no longer reads "docked". `then_poi`: the
        POI the caller drives to next, whose drive the goal's remaining time then counts too (an
        unknown name ends the goal with UNKNOWN_POI before the base moves)."""
        ...

    def get_labware(
        self, handover: LabwareHandover, on_feedback: FeedbackListener | None = None
    ) -> ActionGoal:
        """Take the plate from the station nest of `handover` into its hotel slot. The goal's
        `result` may carry the `labware_id` the robot side read from the plate."""
        ...

    def put_labware(
        self, handover: LabwareHandover, on_feedback: FeedbackListener | None = None
    ) -> ActionGoal:
        """Place the plate of the hotel slot of `handover` into its station nest."""
        ...


__all__ = ["FeedbackListener", "RobotBackend", "StationBackend"]
