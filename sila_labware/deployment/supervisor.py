"""Keep the robot side of a deployment alive: notice a dead child or a dead ROS thread at once,
fail the running command with a defined error, restart, and re-synchronise the inventory.

Why a supervisor and not only ROS timeouts: a killed node leaves the bridge's goal waiting for a
result that never comes (DDS notices a dead participant only after its lease, ~20 s). The
process that started the child knows within one poll period that it is gone. Likewise the
bridge's own ROS thread: once it has ended (an rclpy callback raised), no answer reaches any goal
and every SiLA command would fail with "the ROS runtime is not running" for good.

Policy (documented in README, "Reliability"):
- any robot-side child ending (sim node or sequencer) restarts the whole robot side: the two
  nodes share goals, and a fresh simulation starts from the world file, so the survivor's state
  would be stale;
- the bridge's ROS thread ending is handled the same way, plus a new ROS runtime under the same
  `RobotLink` (`restart_bridge`): the robot side is restarted too, because the goal it was running
  for the lost runtime can no longer be watched or cancelled;
- while it is down the robot reports state "error" with the reason, the running command ends
  with the feature's defined error (LabwareNotPicked/LabwareNotPlaced, or the motion's error),
  and every plate the inventory knows is marked unknown;
- once the robot side answers again, every plate is put where the fresh observations say
  (hotel, gripper, a nest sensor reporting its id), or stays unknown - never the old guess;
- after `max_restarts` restarts within `restart_window_s` the supervisor gives up and
  `failure` names why (the CLI then exits non-zero).

Threads: one daemon thread polls the children and the ROS thread; restarts run on it.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from labware_model.holders import location_text
from ros_bridge.errors import BridgeError
from ros_bridge.robot_link import RobotLink
from sila_labware.deployment.processes import ProcessGroup
from sila_labware.device.robot_controller import RobotController

logger = logging.getLogger(__name__)


INVENTORY_AFTER_RESTART_S = 5.0
"""How long the new robot side has to publish an inventory that follows its fresh sensors."""

ROS_THREAD = "ros_thread"
"""The name a restart record gives the bridge's ROS thread (the children go by theirs)."""


@dataclass
class RestartRecord:
    """One restart: which child ended (or ROS_THREAD), with which exit code (None for the ROS
    thread), and how long recovery took."""

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


@dataclass(frozen=True)
class _Loss:
    """What the supervisor found gone: a child (name, exit code) or the ROS thread (why)."""

    name: str
    exit_code: int | None
    what: str  # "sim_node ended (exit code -9)"


@dataclass
class RobotSideSupervisor:
    """Watches `children` and the link's ROS thread; `start_robot_side` starts the children again
    (both nodes), `restart_bridge` (if given) puts the link on a new ROS runtime."""

    children: ProcessGroup
    start_robot_side: Callable[[], None]
    link: RobotLink
    robot: RobotController
    settings: SupervisorSettings = field(default_factory=SupervisorSettings)
    restarts: list[RestartRecord] = field(default_factory=list)
    failure: str = ""
    restart_bridge: Callable[[], None] | None = None

    def __post_init__(self) -> None:
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._watch, name="robot-side-supervisor", daemon=True)

    def start(self) -> RobotSideSupervisor:
        self._thread.start()
        return self

    def stop(self, timeout_s: float = 1.0) -> None:
        """Stop watching; wait up to `timeout_s` for a restart under way to notice. The owner must
        refuse further restarts itself (`Deployment.stop` does): a daemon thread still inside one
        after the wait finds its starts refused and ends."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout_s)

    @property
    def recovering(self) -> bool:
        return bool(self.restarts) and self.restarts[-1].ready_after_s is None and not self.failure

    def _watch(self) -> None:
        while not self._stop.wait(self.settings.poll_period_s):
            loss = self._find_loss()
            if loss is None or self._stop.is_set():  # a stop ends the children: no loss then
                continue
            if loss.name == ROS_THREAD and self.restart_bridge is None:
                self._give_up(f"{loss.what}, and this deployment cannot restart the bridge")
                return
            if not self._may_restart():
                self._give_up(
                    f"{loss.what} and the robot side was already restarted {self.settings.max_restarts} "
                    f"times within {self.settings.restart_window_s:.0f} s"
                )
                return
            self._recover(loss)

    def _find_loss(self) -> _Loss | None:
        failure = self.link.runtime.failure
        if failure:
            return _Loss(ROS_THREAD, None, f"the bridge's ROS thread ended ({failure})")
        for child in self.children.children:
            if not child.running:
                code = child.popen.returncode
                tail = child.log_tail(lines=8)
                if tail:  # why it ended: its own last words, before a restart starts it anew
                    logger.error("%s ended (exit code %s); the end of its log:\n%s", child.name, code, tail)
                return _Loss(child.name, code, f"{child.name} ended (exit code {code})")
        return None

    def _give_up(self, failure: str) -> None:
        self.failure = failure
        logger.error("%s: giving up", failure)
        self.link.mark_robot_side_lost(failure)
        self.robot.abort_active_goal(failure)

    def _may_restart(self) -> bool:
        window_start = time.monotonic() - self.settings.restart_window_s
        return sum(record.started_at >= window_start for record in self.restarts) < self.settings.max_restarts

    def _recover(self, loss: _Loss) -> None:
        """Restart what `loss` calls for; `failure` says why if that failed."""
        record = RestartRecord(loss.name, loss.exit_code, time.monotonic())
        self.restarts.append(record)
        bridge_lost = loss.name == ROS_THREAD
        restarting = "the bridge and the robot side" if bridge_lost else "it"
        reason = f"robot side lost: {loss.what}; restarting {restarting}"
        logger.error("%s", reason)
        self.link.mark_robot_side_lost(reason)
        self.robot.abort_active_goal(reason)
        revision_at_loss = self.robot.inventory.revision
        self.robot.inventory.mark_all_unknown()
        self.children.stop(timeout_s=2.0)
        # The surviving node published until it was stopped; let its last samples arrive, then
        # mark the side lost again so only the new robot side's state counts as "back".
        time.sleep(0.5)
        try:
            if bridge_lost:
                assert self.restart_bridge is not None  # checked in _watch
                self.restart_bridge()
            self.link.mark_robot_side_lost(reason)
            self.start_robot_side()
            self._wait_until_ready()
        except Exception as error:  # noqa: BLE001 - ChildExited, BridgeError, OSError: give up, say why
            self.failure = f"restarting the robot side failed: {error}"
            logger.error("%s", self.failure)
            return
        self._resynchronise_inventory(revision_at_loss)
        record.ready_after_s = time.monotonic() - record.started_at
        logger.warning("robot side back after %.1f s", record.ready_after_s)

    def _wait_until_ready(self) -> None:
        deadline = time.monotonic() + self.settings.ready_timeout_s
        while not self._stop.is_set():
            self.children.check_running()
            if self.link.runtime.failure:
                raise BridgeError(f"the new ROS thread ended as well ({self.link.runtime.failure})")
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

    def _resynchronise_inventory(self, revision_at_loss: int) -> None:
        """Wait for the new robot side's inventory: it kept its names in its file and put every
        plate where its fresh sensors see it (labware_model.inventory), or marked it unknown."""
        try:
            snapshot = self.link.wait_for_inventory(
                lambda snapshot: snapshot.revision > revision_at_loss, INVENTORY_AFTER_RESTART_S
            )
        except BridgeError:
            logger.warning("the new robot side published no newer inventory: plates stay unknown")
            return
        self.robot.inventory.replace(snapshot)
        for labware in snapshot.records:
            logger.info(
                "after restart, %s observed at %s", labware.labware_id, location_text(labware.location)
            )
