"""An in-memory robot back end (a `RobotBackend`) for millisecond tests of the device logic.

The test sets what the robot reports (its state, the nest sensors) and scripts how each goal
ends: `succeed()` (the robot state then shows the goal's natural effect: at the POI, docked, the
plate moved between nest and hotel), `fail(code)`, `never_ends()` (no answer, cancel refused),
`ends_when_cancelled()`, `rejected()` or `unsendable()`. Unscripted goals succeed. Each goal is a
real `ActionGoal` finished by the fake, as the ROS bridge's ROS thread finishes it in a
deployment; every goal sent is recorded in `sent`.

Like the robot side, it keeps the one inventory (a `labware_model.inventory.LabwareBook`): a
transfer names its plate at the source and settles it on presence; what the test sets between
transfers is followed as the robot side follows its sensors. Readers get it as `inventory()`.

Threads: a goal that ends does so inside the call that sends it (feedback first, then the end),
on the calling thread; one scripted to wait is finished by a cancel request, on the canceller's
thread. State waits use a condition, so a test may change the state from another thread.
"""

from __future__ import annotations

import enum
import threading
import time
from collections import defaultdict, deque
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from types import SimpleNamespace
from typing import Any

from labware_model.holders import GRIPPER, HotelSlot, Location, Nest
from labware_model.inventory import LabwareBook, NameTaken, sensed_plates
from labware_model.readings import HotelSlotReading, NestReading
from ros_bridge.errors import BridgeError, BridgeTimeout
from ros_bridge.goal_status import ActionGoal, ActionOutcome
from ros_bridge.progress import GoalProgress
from ros_bridge.workcell import InventorySnapshot, LabwareHandover, RobotStatus

FeedbackListener = Callable[[GoalProgress], None]


class GoalEnd(enum.Enum):
    SUCCEED = "succeed"
    FAIL = "fail"
    NEVER = "never ends"
    WHEN_CANCELLED = "ends when cancelled"
    REJECTED = "rejected"
    UNSENDABLE = "cannot be sent"


@dataclass(frozen=True)
class ScriptedGoal:
    """How one goal goes: feedback fractions, a hook while it runs, how it ends, what it leaves."""

    end: GoalEnd = GoalEnd.SUCCEED
    error_code: str = ""
    message: str = ""
    feedback: tuple[float, ...] = ()
    while_running: Callable[[], None] | None = None
    """Called on the sending thread after the feedback and before the end (a second command)."""
    robot_after: RobotStatus | None = None
    """The robot state once the goal ends, instead of its natural effect (success) or no change."""
    nests_after: tuple[NestReading, ...] | None = None
    result: Any = None


def succeed(**details: Any) -> ScriptedGoal:
    return ScriptedGoal(GoalEnd.SUCCEED, **details)


def fail(error_code: str, message: str = "", **details: Any) -> ScriptedGoal:
    return ScriptedGoal(GoalEnd.FAIL, error_code, message or f"scripted failure {error_code}", **details)


def never_ends(**details: Any) -> ScriptedGoal:
    return ScriptedGoal(GoalEnd.NEVER, **details)


def ends_when_cancelled(**details: Any) -> ScriptedGoal:
    return ScriptedGoal(GoalEnd.WHEN_CANCELLED, **details)


def rejected() -> ScriptedGoal:
    return ScriptedGoal(GoalEnd.REJECTED)


def unsendable() -> ScriptedGoal:
    return ScriptedGoal(GoalEnd.UNSENDABLE)


def robot_state(
    state: str = "idle", poi: str = "", hotel: dict[int, str] | None = None, held: str = ""
) -> RobotStatus:
    """A robot state with hotel slot -> plate id (empty string: free); two free slots by default."""
    slots = tuple(
        HotelSlotReading(HotelSlot(index), plate, "") for index, plate in (hotel or {1: "", 2: ""}).items()
    )
    return RobotStatus(state, "", poi, 0.0, 0.0, 0.0, slots, held)


def nest(station: str, sub_position: int, plate: str = "", occupied: bool | None = None) -> NestReading:
    """A nest reading; occupied when it holds a plate unless `occupied` says otherwise."""
    return NestReading(Nest(station, sub_position), bool(plate) if occupied is None else occupied, plate)


@dataclass
class SentGoal:
    """One goal the device logic sent: which action, with what, its status, cancel requests."""

    action: str
    argument: Any
    goal: ActionGoal
    cancel_requests: list[float] = field(default_factory=list)


class FakeRobot:
    """Satisfies `sila_labware.device.robot_backend.RobotBackend` in memory."""

    def __init__(self, robot: RobotStatus | None = None, nests: tuple[NestReading, ...] = ()) -> None:
        self._changed = threading.Condition()
        self._robot = robot or robot_state()
        self._nests = tuple(nests)
        self._listeners: list[Callable[[RobotStatus], None]] = []
        self._scripts: dict[str, deque[ScriptedGoal]] = defaultdict(deque)
        self.sent: list[SentGoal] = []
        self.book = LabwareBook()
        self._inventory = InventorySnapshot(1, ())
        self._inventory_listeners: list[Callable[[InventorySnapshot], None]] = []
        self._follow_sensors()

    # --- the test's controls ---

    def script(self, action: str, *goals: ScriptedGoal) -> None:
        """Queue how the next goals of `action` ("navigate_to_poi", "dock", ...) go."""
        self._scripts[action].extend(goals)

    def set_robot_status(self, robot: RobotStatus) -> None:
        """What the robot reports from now on; the inventory follows it (between transfers)."""
        self._report_robot(robot)
        self._follow_sensors()

    def set_nests(self, nests: tuple[NestReading, ...]) -> None:
        """What the nest sensors report from now on; the inventory follows them."""
        self._report_nests(nests)
        self._follow_sensors()

    def _report_robot(self, robot: RobotStatus) -> None:
        with self._changed:
            changed, self._robot = robot != self._robot, robot
            listeners = list(self._listeners) if changed else []
            self._changed.notify_all()
        for listener in listeners:
            listener(robot)

    def _report_nests(self, nests: tuple[NestReading, ...]) -> None:
        with self._changed:
            self._nests = tuple(nests)
            self._changed.notify_all()

    def _sensed(self) -> tuple[Any, set[Location]]:
        robot, nests = self.robot_status(), self.nest_readings()
        plates = sensed_plates(robot.hotel, robot.holding, robot.held_labware_id, nests)
        return plates, {r.slot for r in robot.hotel} | {r.nest for r in nests} | {GRIPPER}

    def _follow_sensors(self) -> None:
        if self.book.reconcile(*self._sensed()):
            self._publish_inventory()

    def _publish_inventory(self) -> None:
        with self._changed:
            self._inventory = InventorySnapshot(self._inventory.revision + 1, self.book.records())
            snapshot, listeners = self._inventory, list(self._inventory_listeners)
            self._changed.notify_all()
        for listener in listeners:
            listener(snapshot)

    def actions_sent(self) -> list[str]:
        return [sent.action for sent in self.sent]

    # --- RobotBackend: state ---

    def robot_status(self, timeout_s: float = 5.0) -> RobotStatus:
        with self._changed:
            return self._robot

    def wait_for_robot_status(
        self, predicate: Callable[[RobotStatus], bool], timeout_s: float = 5.0
    ) -> RobotStatus:
        with self._changed:
            if not self._changed.wait_for(lambda: predicate(self._robot), timeout_s):
                raise BridgeTimeout(f"no matching message on /robot_state within {timeout_s:.1f} s")
            return self._robot

    def on_robot_status(self, listener: Callable[[RobotStatus], None]) -> None:
        with self._changed:
            self._listeners.append(listener)

    def nest_readings(self, timeout_s: float = 5.0) -> tuple[NestReading, ...]:
        with self._changed:
            return self._nests

    def inventory(self, timeout_s: float = 5.0) -> InventorySnapshot:
        with self._changed:
            return self._inventory

    def wait_for_inventory(
        self, predicate: Callable[[InventorySnapshot], bool], timeout_s: float = 5.0
    ) -> InventorySnapshot:
        with self._changed:
            if not self._changed.wait_for(lambda: predicate(self._inventory), timeout_s):
                raise BridgeTimeout(f"no matching message on /labware_inventory within {timeout_s:.1f} s")
            return self._inventory

    def on_inventory(self, listener: Callable[[InventorySnapshot], None]) -> None:
        with self._changed:
            self._inventory_listeners.append(listener)

    def wait_for_nest(self, nest: Nest, occupied: bool, timeout_s: float = 5.0) -> None:
        def shows() -> bool:
            return any((reading.nest, reading.occupied) == (nest, occupied) for reading in self._nests)

        with self._changed:
            if not self._changed.wait_for(shows, timeout_s):
                raise BridgeTimeout(f"no matching message on /station_states within {timeout_s:.1f} s")

    # --- RobotBackend: goals ---

    def navigate_to_poi(self, poi: str, on_feedback: FeedbackListener | None = None) -> ActionGoal:
        return self._send("navigate_to_poi", poi, on_feedback)

    def dock(self, on_feedback: FeedbackListener | None = None) -> ActionGoal:
        return self._send("dock", None, on_feedback)

    def undock(self, on_feedback: FeedbackListener | None = None, then_poi: str = "") -> ActionGoal:
        return self._send("undock", then_poi, on_feedback)

    def get_labware(
        self, handover: LabwareHandover, on_feedback: FeedbackListener | None = None
    ) -> ActionGoal:
        return self._send("get_labware", handover, on_feedback)

    def put_labware(
        self, handover: LabwareHandover, on_feedback: FeedbackListener | None = None
    ) -> ActionGoal:
        return self._send("put_labware", handover, on_feedback)

    # --- helpers ---

    def _send(self, action: str, argument: Any, on_feedback: FeedbackListener | None) -> ActionGoal:
        script = self._scripts[action].popleft() if self._scripts[action] else succeed()
        if script.end is GoalEnd.UNSENDABLE:
            raise BridgeError(f"/{action}: the ROS runtime is not running")

        def cancel_request(timeout_s: float) -> bool:
            return self._cancel(sent, script, timeout_s)

        sent = SentGoal(action, argument, ActionGoal(f"/{action}", cancel_request))
        goal = sent.goal
        if on_feedback is not None:
            goal.add_progress_listener(on_feedback)
        self.sent.append(sent)
        if script.end is GoalEnd.REJECTED:
            goal.set_rejected()
            return goal
        goal.set_accepted()
        try:
            name = self._name_plate(action, argument)
        except NameTaken as taken:
            goal.set_finished(ActionOutcome(False, "LABWARE_ELSEWHERE", str(taken), "ABORTED", None))
            return goal
        for fraction in script.feedback:
            goal.update_progress(fraction, action, 1.0 - fraction)
        if script.while_running is not None:
            script.while_running()
        if script.end is GoalEnd.SUCCEED:
            self._apply(script.robot_after or self._natural_effect(action, argument), script.nests_after)
            result = self._settle(action, argument, name, script.result)
            goal.set_finished(ActionOutcome(True, "", f"{action} done", "SUCCEEDED", result))
        elif script.end is GoalEnd.FAIL:
            self._apply(script.robot_after, script.nests_after)
            result = self._settle(action, argument, name, script.result)
            goal.set_finished(ActionOutcome(False, script.error_code, script.message, "ABORTED", result))
        return goal

    def _name_plate(self, action: str, argument: Any) -> str:
        """A transfer names its plate at its source before anything moves (as the sequencer does)."""
        if action not in ("get_labware", "put_labware"):
            return ""
        handover: LabwareHandover = argument
        source = handover.nest if action == "get_labware" else handover.hotel_slot
        label = self._label_at(source)
        before = self.book.records()
        record = self.book.name_plate(source, handover.labware_id, handover.labware_type, label)
        if self.book.records() != before:
            self._publish_inventory()
        return record.labware_id if record is not None else ""

    def _settle(self, action: str, argument: Any, name: str, scripted: Any) -> Any:
        """After a transfer: its plate where presence says; the result names it and the revision."""
        if action not in ("get_labware", "put_labware"):
            return scripted
        handover: LabwareHandover = argument
        getting = action == "get_labware"
        source, destination = (
            (handover.nest, handover.hotel_slot) if getting else (handover.hotel_slot, handover.nest)
        )
        if name and self.book.settle(name, (destination, GRIPPER, source), self._sensed()[0]):
            self._publish_inventory()
        if scripted is not None:
            return scripted
        return SimpleNamespace(labware_id=name, inventory_revision=self.inventory().revision)

    def _label_at(self, holder: Location) -> str:
        if isinstance(holder, Nest):
            return next((r.labware_id for r in self.nest_readings() if r.nest == holder), "")
        return next((r.labware_id for r in self.robot_status().hotel if r.slot == holder), "")

    def _cancel(self, sent: SentGoal, script: ScriptedGoal, timeout_s: float) -> bool:
        sent.cancel_requests.append(timeout_s)
        if script.end is not GoalEnd.WHEN_CANCELLED:
            return False
        self._apply(script.robot_after, script.nests_after)
        waited_s = time.monotonic() - sent.goal.sent_at
        sent.goal.set_finished(
            ActionOutcome(False, "CANCELED", f"cancelled after {waited_s:.3f} s", "CANCELED", script.result)
        )
        return True

    def _apply(self, robot: RobotStatus | None, nests: tuple[NestReading, ...] | None) -> None:
        """A goal's effect on what the robot reports (the inventory is settled by the goal)."""
        if nests is not None:
            self._report_nests(nests)
        if robot is not None:
            self._report_robot(robot)

    def _natural_effect(self, action: str, argument: Any) -> RobotStatus:
        """What a successful goal leaves: the base at the POI, (un)docked, the plate moved."""
        robot = self.robot_status()
        if action == "navigate_to_poi":
            return replace(robot, state="idle", current_poi=argument)
        if action == "dock":
            return replace(robot, state="docked")
        if action == "undock":
            return replace(robot, state="idle")
        handover: LabwareHandover = argument
        getting = action == "get_labware"
        label = self._label_at(handover.nest if getting else handover.hotel_slot)  # moves with the plate
        hotel = tuple(
            HotelSlotReading(slot.slot, label, handover.labware_type, occupied=True)
            if slot.slot == handover.hotel_slot and getting
            else HotelSlotReading(slot.slot)
            if slot.slot == handover.hotel_slot
            else slot
            for slot in robot.hotel
        )
        self._report_nests(
            tuple(
                NestReading(reading.nest, not getting, "" if getting else label)
                if reading.nest == handover.nest
                else reading
                for reading in self.nest_readings()
            )
        )
        return replace(robot, hotel=hotel)


def result_with_labware_id(labware_id: str) -> SimpleNamespace:
    """A GetLabware result as the robot side returns it when it read the plate's id."""
    return SimpleNamespace(labware_id=labware_id, success=True)
