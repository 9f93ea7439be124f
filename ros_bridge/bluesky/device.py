"""The labware robot as an Ophyd movable: `set(task)` sends a GetLabware/PutLabware goal.

Tasks follow the beamline paper's four types, mapped onto our task-level actions:

    pickup         GetLabware  storage site -> hotel slot
    place          PutLabware  hotel slot   -> beam site
    return_pickup  GetLabware  beam site    -> hotel slot
    return_place   PutLabware  hotel slot   -> storage site

Which station/nest is "storage" and which is "beam" is given to the constructor; the robot side
decides whether a goal is possible and says why not (the status then fails with the action's
error code and message). `read()` reports the robot state from /robot_state (state word, what
the base is near, where it stands) and, from the robot side's one inventory (/labware_inventory,
the same the SiLA servers read), what the robot carries and where every named plate is.
`stop()` cancels every goal this device has running.

Threads: `set`, `trigger`, `read` and `stop` are called from the RunEngine's threads; the
readings are updated on the ROS thread from /robot_state and /labware_inventory
(`RobotLink.on_robot_status`, `RobotLink.on_inventory`).
"""

from __future__ import annotations

import enum
import logging
import threading
import time
from collections.abc import Mapping
from typing import Any

from ophyd import Component, Device, Signal, SignalRO
from ophyd.status import DeviceStatus

from labware_model.holders import GRIPPER, HotelSlot, Nest, aboard, location_text
from ros_bridge.bluesky.status import ActionStatus
from ros_bridge.errors import BridgeError
from ros_bridge.robot_link import LabwareHandover, RobotLink
from ros_bridge.workcell import InventorySnapshot, RobotStatus

logger = logging.getLogger(__name__)


class TransferTask(str, enum.Enum):
    """The four task types of the beamline paper."""

    PICKUP = "pickup"
    PLACE = "place"
    RETURN_PICKUP = "return_pickup"
    RETURN_PLACE = "return_place"


class RobotReading(SignalRO):
    """A read-only reading the robot reports; only the device updates it (from /robot_state)."""

    def report(self, value: Any, timestamp: float | None = None) -> None:
        if value != self._readback:
            Signal.put(self, value, timestamp=timestamp, force=True)


def _joined(labware_ids: tuple[str, ...]) -> str:
    return ",".join(labware_ids)


class LabwareTransferRobot(Device):
    """A mobile manipulator moving one plate between a storage nest and a beam (measurement) nest."""

    state = Component(RobotReading, value="", kind="hinted")
    carried_labware = Component(RobotReading, value="", kind="hinted")
    held_labware = Component(RobotReading, value="", kind="normal")
    labware_locations = Component(RobotReading, value="", kind="normal")
    """Every plate the robot side's inventory names: "name=location" joined by commas."""
    current_poi = Component(RobotReading, value="", kind="normal")
    detail = Component(RobotReading, value="", kind="normal")
    base_x = Component(RobotReading, value=0.0, kind="normal")
    base_y = Component(RobotReading, value=0.0, kind="normal")
    base_theta = Component(RobotReading, value=0.0, kind="normal")
    last_task = Component(RobotReading, value="", kind="normal")
    storage_site = Component(RobotReading, value="", kind="config")
    beam_site = Component(RobotReading, value="", kind="config")
    hotel_slot = Component(RobotReading, value=0, kind="config")
    labware_id = Component(RobotReading, value="", kind="config")

    def __init__(
        self,
        link: RobotLink,
        *,
        storage: Nest,
        beam: Nest,
        labware_id: str,
        labware_type: str = "",
        hotel_slot: int = 1,
        task_timeout_s: float = 600.0,
        name: str = "robot",
        **kwargs: Any,
    ) -> None:
        super().__init__(name=name, **kwargs)
        self.link = link
        self.storage = storage
        self.beam = beam
        self.labware_type = labware_type
        self.task_timeout_s = task_timeout_s
        self.storage_site.report(str(storage))
        self.beam_site.report(str(beam))
        self.hotel_slot.report(int(hotel_slot))
        self.labware_id.report(labware_id)
        self._running: list[ActionStatus] = []
        self._running_lock = threading.Lock()
        link.on_robot_status(self._report_robot_status)
        latest = link.latest_robot_status()
        if latest is not None:
            self._report_robot_status(latest)
        link.on_inventory(self._report_inventory)
        try:
            self._report_inventory(link.inventory(timeout_s=0.0))
        except BridgeError:
            pass  # none yet: the first one is reported when it comes

    @property
    def current_status(self) -> ActionStatus | None:
        """The status of the latest task sent (running or ended), None before the first."""
        with self._running_lock:
            return self._running[-1] if self._running else None

    # --- bluesky Movable / Stoppable / Triggerable ---

    def set(self, value: str | TransferTask | Mapping[str, Any], **_kwargs: Any) -> ActionStatus:
        """Send the task-level goal for `value` ("pickup", ... or {"task": ..., "labware_id": ...})."""
        task, labware_id = self._parse_task(value)
        hotel_slot = int(self.hotel_slot.get())
        site = self.storage if task in (TransferTask.PICKUP, TransferTask.RETURN_PLACE) else self.beam
        label = f"{task.value} {labware_id} {'from' if _is_get(task) else 'to'} {site}"
        send = self.link.get_labware if _is_get(task) else self.link.put_labware
        logger.info("%s: %s (hotel slot %d)", self.name, label, hotel_slot)
        handover = LabwareHandover(site, HotelSlot(hotel_slot), self.labware_type, labware_id)
        goal = send(handover)
        status = ActionStatus(self, goal, label=label, timeout=self.task_timeout_s)
        self.last_task.report(task.value)
        with self._running_lock:
            self._running = [running for running in self._running if not running.done] + [status]
        return status

    def stop(self, *, success: bool = False) -> None:
        """Cancel every goal of this device that is still running (returns at once)."""
        with self._running_lock:
            running = [status for status in self._running if not status.done]
        for status in running:
            logger.info("%s: stop (success=%s) cancels %s", self.name, success, status.label)
            status.cancel_goal()

    def trigger(self) -> DeviceStatus:
        """Done when a /robot_state newer than this call has arrived, so `read()` is current."""
        status = DeviceStatus(self, timeout=10.0)
        threading.Thread(
            target=self._refresh, args=(status,), name=f"{self.name}-trigger", daemon=True
        ).start()
        return status

    # --- helpers ---

    def _refresh(self, status: DeviceStatus, wait_s: float = 5.0) -> None:
        asked_at = time.time()
        try:
            known = self.link.robot_status(wait_s)
            fresh = self.link.wait_for_robot_status(lambda robot: robot.stamp_s > known.stamp_s, wait_s)
        except BridgeError as error:
            status.set_exception(error)
            return
        self._report_robot_status(fresh, max(asked_at, time.time()))
        status.set_finished()

    def _report_robot_status(self, robot: RobotStatus, timestamp: float | None = None) -> None:
        received_at = time.time() if timestamp is None else timestamp
        self.state.report(robot.state, received_at)
        self.current_poi.report(robot.current_poi, received_at)
        self.detail.report(robot.detail, received_at)
        self.base_x.report(robot.x_m, received_at)
        self.base_y.report(robot.y_m, received_at)
        self.base_theta.report(robot.theta_rad, received_at)

    def _report_inventory(self, inventory: InventorySnapshot) -> None:
        received_at = time.time()
        records = inventory.records
        self.carried_labware.report(
            _joined(tuple(r.labware_id for r in records if aboard(r.location))), received_at
        )
        self.held_labware.report(
            next((r.labware_id for r in records if r.location == GRIPPER), ""), received_at
        )
        self.labware_locations.report(
            _joined(tuple(f"{r.labware_id}={location_text(r.location)}" for r in records)), received_at
        )

    def _parse_task(self, value: str | TransferTask | Mapping[str, Any]) -> tuple[TransferTask, str]:
        labware_id = str(self.labware_id.get())
        if isinstance(value, Mapping):
            labware_id = str(value.get("labware_id", labware_id))
            value = value.get("task", "")
        try:
            return TransferTask(value), labware_id
        except ValueError:
            known = ", ".join(task.value for task in TransferTask)
            raise ValueError(f"{self.name}: unknown task {value!r}; expected one of {known}") from None


def _is_get(task: TransferTask) -> bool:
    return task in (TransferTask.PICKUP, TransferTask.RETURN_PICKUP)
