"""The robot as the SiLA side sees it: named actions, services and state topics of labware_interfaces.

This is the back end under the SiLA feature implementations. It knows the ROS names of the
contract (/navigate_to_poi, /get_labware, /robot_state, ...) and converts messages into the
plain snapshots of `workcell.py`. It knows nothing of the simulation: a real robot that serves
the same names works unchanged.

Its ROS endpoints (action and service clients, topic mirrors) live on one `RosRuntime`; `attach`
moves the link to a new runtime when the old one's ROS thread has died, keeping the link object,
its listeners and its last state, so everything built on it (controllers, SiLA features) goes on.

Threads: construct and call from any thread except the ROS thread; every wait is on a future
with a timeout. Listeners registered here run on the ROS thread (on the supervisor's thread for
`mark_robot_side_lost` when the ROS thread is gone).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass

from labware_interfaces.action import Dock, GetLabware, NavigateToPoi, PutLabware, Undock
from labware_interfaces.msg import LabwareInventory, RobotState, StationStates
from labware_interfaces.srv import CheckPlacement, DescribeWorkcell

from labware_model.holders import UNKNOWN, HotelSlot, Nest, parse_location
from labware_model.inventory import LabwareRecord
from labware_model.readings import HotelSlotReading, NestReading, PlacementCheck
from labware_model.workcell import WorkcellDescription
from ros_bridge.actions import ActionCaller, ActionGoal, GoalProgress
from ros_bridge.errors import BridgeError
from ros_bridge.runtime import RosRuntime
from ros_bridge.services import ServiceCaller
from ros_bridge.topics import INVENTORY_QOS, TopicMirror
from ros_bridge.workcell import InventorySnapshot, LabwareHandover, RobotStatus

logger = logging.getLogger(__name__)

FeedbackListener = Callable[[GoalProgress], None]


def robot_status_from_message(message: RobotState) -> RobotStatus:
    return RobotStatus(
        state=message.state,
        detail=message.detail,
        current_poi=message.current_poi,
        x_m=float(message.base_pose.x),
        y_m=float(message.base_pose.y),
        theta_rad=float(message.base_pose.theta),
        hotel=tuple(
            HotelSlotReading(HotelSlot(int(slot.index)), slot.labware_id, slot.labware_type, slot.occupied)
            for slot in message.hotel
        ),
        held_labware_id=message.held_labware_id,
        stamp_s=message.stamp.sec + message.stamp.nanosec * 1e-9,
        holding=message.holding,
    )


def nest_readings_from_message(message: StationStates) -> tuple[NestReading, ...]:
    return tuple(
        NestReading(Nest(nest.station, int(nest.sub_position)), bool(nest.occupied), nest.labware_id)
        for nest in message.nests
    )


def inventory_from_message(message: LabwareInventory) -> InventorySnapshot:
    """The records of a /labware_inventory message; a record with an unreadable location is
    taken as unknown (and logged): the inventory never guesses."""
    records = []
    for record in message.records:
        try:
            location = parse_location(record.location)
        except ValueError:
            logger.error(
                "/labware_inventory: %s has an unreadable location %r", record.labware_id, record.location
            )
            location = UNKNOWN
        records.append(LabwareRecord(record.labware_id, record.labware_type, location, record.label))
    return InventorySnapshot(int(message.revision), tuple(records))


@dataclass(frozen=True)
class _Endpoints:
    """The link's clients and mirrors on one runtime; replaced as a whole by `RobotLink.attach`."""

    runtime: RosRuntime
    navigate: ActionCaller
    dock: ActionCaller
    undock: ActionCaller
    get_labware: ActionCaller
    put_labware: ActionCaller
    describe: ServiceCaller
    check_placement: ServiceCaller
    robot_state: TopicMirror
    station_states: TopicMirror
    inventory: TopicMirror

    @classmethod
    def create(
        cls,
        runtime: RosRuntime,
        on_robot_state: Callable[[RobotState], None],
        on_station_states: Callable[[StationStates], None],
        on_inventory: Callable[[LabwareInventory], None],
    ) -> _Endpoints:
        return cls(
            runtime,
            ActionCaller(runtime, NavigateToPoi, "/navigate_to_poi"),
            ActionCaller(runtime, Dock, "/dock"),
            ActionCaller(runtime, Undock, "/undock"),
            ActionCaller(runtime, GetLabware, "/get_labware"),
            ActionCaller(runtime, PutLabware, "/put_labware"),
            ServiceCaller(runtime, DescribeWorkcell, "/describe_workcell"),
            ServiceCaller(runtime, CheckPlacement, "/check_placement"),
            TopicMirror(runtime, RobotState, "/robot_state", listeners=[on_robot_state]),
            TopicMirror(runtime, StationStates, "/station_states", listeners=[on_station_states]),
            TopicMirror(
                runtime, LabwareInventory, "/labware_inventory", qos=INVENTORY_QOS, listeners=[on_inventory]
            ),
        )


class RobotLink:
    """Clients of every robot-side action, service and topic, sharing one `RosRuntime`.

    It is the ROS back end of `sila_labware.device.robot_backend.RobotBackend` (checked by the
    tests); that protocol's docstrings state the units, errors and threads of the methods it names."""

    def __init__(self, runtime: RosRuntime) -> None:
        self._status_listeners: list[Callable[[RobotStatus], None]] = []
        self._nest_listeners: list[Callable[[tuple[NestReading, ...]], None]] = []
        self._inventory_listeners: list[Callable[[InventorySnapshot], None]] = []
        self._ros = self._endpoints(runtime)

    @property
    def runtime(self) -> RosRuntime:
        """The runtime the link's endpoints live on now."""
        return self._ros.runtime

    def attach(self, runtime: RosRuntime) -> None:
        """Rebuild every endpoint on `runtime` (started), for a link whose runtime died: listeners
        stay registered, and the last robot state and nest readings are carried over until the new
        robot side publishes. The old runtime's entities are its own to destroy (`stop()`)."""
        previous = self._ros
        endpoints = self._endpoints(runtime)
        for old, new in (
            (previous.robot_state, endpoints.robot_state),
            (previous.station_states, endpoints.station_states),
            (previous.inventory, endpoints.inventory),
        ):
            last = old.latest
            if last is not None:  # on the ROS thread: no real message can come in between
                runtime.call(lambda mirror=new, message=last: _inject_unless_received(mirror, message))
        self._ros = endpoints
        logger.info("robot link attached to a new ROS runtime")

    def _endpoints(self, runtime: RosRuntime) -> _Endpoints:
        return _Endpoints.create(
            runtime, self._tell_status_listeners, self._tell_nest_listeners, self._tell_inventory_listeners
        )

    def wait_until_ready(self, timeout_s: float = 30.0) -> None:
        """Wait for every action server, service and state topic; raise ServerUnavailable naming one."""
        ros = self._ros
        for action in (ros.navigate, ros.dock, ros.undock, ros.get_labware, ros.put_labware):
            action.wait_for_server(timeout_s)
        for service in (ros.describe, ros.check_placement):
            service.wait_for_service(timeout_s)
        ros.robot_state.wait_for_message(timeout_s)
        ros.station_states.wait_for_message(timeout_s)
        ros.inventory.wait_for_message(timeout_s)

    # --- actions: each returns a goal handle at once (wait on it, cancel it) ---

    def navigate_to_poi(self, poi: str, on_feedback: FeedbackListener | None = None) -> ActionGoal:
        return self._ros.navigate.send(NavigateToPoi.Goal(poi=poi), on_feedback)

    def dock(self, on_feedback: FeedbackListener | None = None) -> ActionGoal:
        return self._ros.dock.send(Dock.Goal(), on_feedback)

    def undock(self, on_feedback: FeedbackListener | None = None, then_poi: str = "") -> ActionGoal:
        return self._ros.undock.send(Undock.Goal(then_poi=then_poi), on_feedback)

    def get_labware(
        self, handover: LabwareHandover, on_feedback: FeedbackListener | None = None
    ) -> ActionGoal:
        """Take the plate from the station nest into the hotel slot."""
        return self._ros.get_labware.send(handover.goal(GetLabware.Goal), on_feedback)

    def put_labware(
        self, handover: LabwareHandover, on_feedback: FeedbackListener | None = None
    ) -> ActionGoal:
        """Place the plate of the hotel slot into the station nest."""
        return self._ros.put_labware.send(handover.goal(PutLabware.Goal), on_feedback)

    # --- services ---

    def describe_workcell(self, timeout_s: float = 5.0) -> WorkcellDescription:
        return WorkcellDescription.from_message(
            self._ros.describe.call(DescribeWorkcell.Request(), timeout_s)
        )

    def check_placement(
        self, labware_id: str, nest: Nest | None = None, timeout_s: float = 5.0
    ) -> PlacementCheck:
        """The robot side's ground truth about a plate, and whether it rests in `nest` (if given).

        For success checks and tests only, never for control; raises BridgeError if the answer
        names a location the labware model does not know."""
        request = CheckPlacement.Request(labware_id=labware_id)
        if nest is not None:
            request.station, request.sub_position = nest.station, nest.sub_position
        response = self._ros.check_placement.call(request, timeout_s)
        try:
            location = parse_location(response.location)
        except ValueError as error:
            raise BridgeError(f"/check_placement answered an unreadable location: {error}") from error
        return PlacementCheck(
            found=bool(response.found),
            in_nest=bool(response.in_nest),
            position_error_m=float(response.position_error_m),
            yaw_error_rad=float(response.yaw_error_rad),
            location=location,
            outside=response.outside,
        )

    # --- state topics ---

    def robot_status(self, timeout_s: float = 5.0) -> RobotStatus:
        """The latest robot state (waits for the first message up to `timeout_s`)."""
        return robot_status_from_message(self._ros.robot_state.wait_for_message(timeout_s))

    def latest_robot_status(self) -> RobotStatus | None:
        message = self._ros.robot_state.latest
        return None if message is None else robot_status_from_message(message)

    def nest_readings(self, timeout_s: float = 5.0) -> tuple[NestReading, ...]:
        """The latest sensor reading of every nest (waits for the first message up to `timeout_s`)."""
        return nest_readings_from_message(self._ros.station_states.wait_for_message(timeout_s))

    def next_nest_readings(self, timeout_s: float = 5.0) -> tuple[NestReading, ...]:
        """The nest readings of the next /station_states message to arrive (not the latest one)."""
        mirror = self._ros.station_states
        current = mirror.latest
        return nest_readings_from_message(
            mirror.wait_for_message(timeout_s, lambda message: message is not current)
        )

    def wait_for_robot_status(
        self, predicate: Callable[[RobotStatus], bool], timeout_s: float = 5.0
    ) -> RobotStatus:
        message = self._ros.robot_state.wait_for_message(
            timeout_s, lambda message: predicate(robot_status_from_message(message))
        )
        return robot_status_from_message(message)

    def wait_for_nest(self, nest: Nest, occupied: bool, timeout_s: float = 5.0) -> None:
        """Wait until the sensor of `nest` reports `occupied`."""

        def matches(message: StationStates) -> bool:
            return any(
                state.station == nest.station
                and state.sub_position == nest.sub_position
                and state.occupied == occupied
                for state in message.nests
            )

        self._ros.station_states.wait_for_message(timeout_s, matches)

    def on_robot_status(self, listener: Callable[[RobotStatus], None]) -> None:
        """Call `listener(status)` on every change of /robot_state (on the ROS thread)."""
        self._status_listeners.append(listener)

    def mark_robot_side_lost(self, reason: str) -> None:
        """Show locally that the robot side is gone: state "error" with `reason`, nothing observed
        aboard (a dead robot side reports nothing). Listeners see it like a received message;
        the next real /robot_state replaces it. Used by the deployment's supervisor; works also when
        the ROS thread is gone (then the listeners run on the calling thread)."""
        message = RobotState(state=RobotState.STATE_ERROR, detail=reason)
        ros = self._ros
        try:
            ros.runtime.call(lambda: ros.robot_state.inject(message))
        except BridgeError:  # no ROS thread to deliver it: nobody else calls the listeners now
            ros.robot_state.inject(message)

    def inventory(self, timeout_s: float = 5.0) -> InventorySnapshot:
        """The robot side's latest inventory (waits for the first message up to `timeout_s`)."""
        return inventory_from_message(self._ros.inventory.wait_for_message(timeout_s))

    def wait_for_inventory(
        self, predicate: Callable[[InventorySnapshot], bool], timeout_s: float = 5.0
    ) -> InventorySnapshot:
        message = self._ros.inventory.wait_for_message(
            timeout_s, lambda message: predicate(inventory_from_message(message))
        )
        return inventory_from_message(message)

    def on_inventory(self, listener: Callable[[InventorySnapshot], None]) -> None:
        """Call `listener(snapshot)` on every change of /labware_inventory (on the ROS thread)."""
        self._inventory_listeners.append(listener)

    def on_nest_readings(self, listener: Callable[[tuple[NestReading, ...]], None]) -> None:
        """Call `listener(readings)` on every change of /station_states (on the ROS thread)."""
        self._nest_listeners.append(listener)

    def _tell_status_listeners(self, message: RobotState) -> None:
        status = robot_status_from_message(message)
        for listener in list(self._status_listeners):
            _tell(listener, status, "/robot_state")

    def _tell_inventory_listeners(self, message: LabwareInventory) -> None:
        snapshot = inventory_from_message(message)
        for listener in list(self._inventory_listeners):
            _tell(listener, snapshot, "/labware_inventory")

    def _tell_nest_listeners(self, message: StationStates) -> None:
        readings = nest_readings_from_message(message)
        for listener in list(self._nest_listeners):
            _tell(listener, readings, "/station_states")


def _inject_unless_received(mirror: TopicMirror, message: object) -> None:
    if mirror.latest is None:
        mirror.inject(message)


def _tell(listener: Callable[[object], None], value: object, topic: str) -> None:
    try:
        listener(value)
    except Exception:  # noqa: BLE001 - one broken listener must not keep the others uninformed
        logger.exception("a listener of %s failed", topic)
