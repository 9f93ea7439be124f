"""Keep the robot side of a deployment alive: notice a dead child at once, fail the running
command with a defined error, restart the robot side, and re-synchronise the inventory.

Why a supervisor and not only ROS timeouts: a killed node leaves the bridge's goal waiting for a
result that never comes (DDS notices a dead participant only after its lease, ~20 s). The
process that started the child knows within one poll period that it is gone.

Policy (documented in README, "Reliability"):
- any robot-side child ending (sim node or sequencer) restarts the whole robot side: the two
  nodes share goals, and a fresh simulation starts from the world file, so the survivor's state
  would be stale;
- while it is down the robot reports state "error" with the reason, the running command ends
  with the feature's defined error (LabwareNotPicked/LabwareNotPlaced, or the motion's error),
  and every plate the inventory knows is marked unknown;
- once the robot side answers again, every plate is put where the fresh observations say
  (hotel, gripper, a nest sensor reporting its id), or stays unknown - never the old guess;
- after `max_restarts` restarts within `restart_window_s` the supervisor gives up and
  `failure` names why (the CLI then exits non-zero).

Threads: one daemon thread polls the children; restarts run on it.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from labware_model.holders import UNKNOWN, location_text
from ros_bridge.errors import BridgeError
from ros_bridge.robot_link import RobotLink
from sila_labware.deployment.processes import ProcessGroup
from sila_labware.device.robot_controller import RobotController

logger = logging.getLogger(__name__)


@dataclass
class RestartRecord:
    """One restart: which child ended, with which exit code, and how long recovery took."""

    child: str
    exit_code: int | None
    started_at: float
    ready_after_s: float | None = None


@dataclass
class SupervisorSettings:
    poll_period_s: float = 0.2
    ready_timeout_s: float = 120.0
    max_restarts: int = 5
    restart_window_s: float = 600.0


@dataclass
class RobotSideSupervisor:
    """Watches `children`; `start_robot_side` starts them again (both nodes)."""

    children: ProcessGroup
    start_robot_side: Callable[[], None]
    link: RobotLink
    robot: RobotController
    settings: SupervisorSettings = field(default_factory=SupervisorSettings)
    restarts: list[RestartRecord] = field(default_factory=list)
    failure: str = ""

    def __post_init__(self) -> None:
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._watch, name="robot-side-supervisor", daemon=True)

    def start(self) -> RobotSideSupervisor:
        self._thread.start()
        return self

    def stop(self, timeout_s: float = 5.0) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout_s)

    @property
    def recovering(self) -> bool:
        return bool(self.restarts) and self.restarts[-1].ready_after_s is None and not self.failure

    def _watch(self) -> None:
        while not self._stop.wait(self.settings.poll_period_s):
            dead = next((child for child in self.children.children if not child.running), None)
            if dead is None:
                continue
            if not self._may_restart():
                self.failure = (
                    f"{dead.name} ended (code {dead.popen.returncode}) and the robot side was already "
                    f"restarted {self.settings.max_restarts} times "
                    f"within {self.settings.restart_window_s:.0f} s"
                )
                logger.error("%s: giving up", self.failure)
                self.link.mark_robot_side_lost(self.failure)
                return
            self._recover(dead.name, dead.popen.returncode)

    def _may_restart(self) -> bool:
        window_start = time.monotonic() - self.settings.restart_window_s
        return sum(record.started_at >= window_start for record in self.restarts) < self.settings.max_restarts

    def _recover(self, child_name: str, exit_code: int | None) -> None:
        record = RestartRecord(child_name, exit_code, time.monotonic())
        self.restarts.append(record)
        reason = f"robot side lost: {child_name} ended (exit code {exit_code}); restarting it"
        logger.error("%s", reason)
        self.link.mark_robot_side_lost(reason)
        self.robot.abort_active_goal(reason)
        for labware in self.robot.inventory.records():
            self.robot.inventory.record(labware.labware_id, labware.labware_type, UNKNOWN)
        self.children.stop(timeout_s=2.0)
        # The surviving node published until it was stopped; let its last samples arrive, then
        # mark the side lost again so only the new robot side's state counts as "back".
        time.sleep(0.5)
        self.link.mark_robot_side_lost(reason)
        try:
            self.start_robot_side()
            self._wait_until_ready()
        except Exception as error:  # noqa: BLE001 - ChildExited, BridgeError, OSError: give up, say why
            self.failure = f"restarting the robot side failed: {error}"
            logger.error("%s", self.failure)
            return
        time.sleep(0.5)  # let the new /station_states arrive too
        self._resynchronise_inventory()
        record.ready_after_s = time.monotonic() - record.started_at
        logger.warning("robot side back after %.1f s", record.ready_after_s)

    def _wait_until_ready(self) -> None:
        deadline = time.monotonic() + self.settings.ready_timeout_s
        while not self._stop.is_set():
            self.children.check_running()
            try:
                self.link.wait_until_ready(timeout_s=1.0)
                # A state message of the new robot side, not the one we injected.
                self.link.wait_for_robot_status(
                    lambda status: not status.detail.startswith("robot side"), 10.0
                )
                return
            except BridgeError:
                if time.monotonic() > deadline:
                    raise
        raise BridgeError("stopped while waiting for the robot side")

    def _resynchronise_inventory(self) -> None:
        """Every known plate goes where the new robot side's observations put it, or stays unknown."""
        status = self.link.robot_status()
        nests = self.link.nest_readings()
        for labware in self.robot.inventory.records():
            location = self.robot.inventory.settle(
                labware.labware_id, labware.labware_type, None, status, nests
            )
            logger.info("after restart, %s observed at %s", labware.labware_id, location_text(location))
