"""The robot's behaviour behind its SiLA features: protocol order, checks, ROS goals, inventory.

This is the front-end logic of the active device; the ROS bridge (`RobotLink`) is its back end,
so a real TIAGo++ serving the same ROS names changes nothing here. It never imports sila2: the
feature implementations translate its exceptions into SiLA errors:

- `CommandSequenceError` -> InvalidCommandSequence (RobotBusy for motion commands)
- `ParameterError` -> a validation error naming the parameter
- `TransferFailed` -> LabwareNotPicked / LabwareNotPlaced, with the robot side's message
- `MotionFailed` -> the MobileRobotController error for its ROS error code

A command can be cancelled by its execution (`cancel_command` with the token it runs under, see
`cancellation`) or, whatever runs, by `stop_motion`; either ends it with its defined error.

Threads: methods run on SiLA handler threads and block until the ROS goal ends, waiting on
futures; progress reports are called on the ROS thread (from action feedback).
"""

from __future__ import annotations

import dataclasses
import logging
import threading
from collections.abc import Callable

from ros_bridge.actions import ActionGoal, ActionOutcome, GoalProgress
from ros_bridge.errors import BridgeError, BridgeTimeout
from ros_bridge.robot_link import LabwareHandover, RobotLink
from ros_bridge.workcell import RobotStatus, WorkcellDescription
from sila_labware.device.cancellation import CancelToken, current_token
from sila_labware.device.errors import CommandSequenceError, MotionFailed, ParameterError, TransferFailed
from sila_labware.device.inventory import Inventory, in_hotel
from sila_labware.device.sequences import ManipulatorSequence, PreparedTransfer
from sila_labware.device.validation import (
    Handover,
    check_handover,
    check_intermediate_actions,
    check_internal_position,
    check_text,
)

logger = logging.getLogger(__name__)

ProgressReport = Callable[[float, float], None]
"""Called with (progress 0..1, estimated remaining seconds)."""

INTERMEDIATE_ACTIONS: tuple[str, ...] = ()
"""Fully qualified command identifiers this robot can run between pick and place: none yet."""


class _ScaledReport:
    """Maps a step's own 0..1 progress into [start, end] of the whole command, never going down."""

    def __init__(self, report: ProgressReport | None, start: float, end: float) -> None:
        self._report, self._start, self._end = report, start, end

    def __call__(self, progress: GoalProgress) -> None:
        if self._report is not None:
            overall = self._start + (self._end - self._start) * progress.progress
            self._report(overall, progress.remaining_time_s)


class RobotController:
    """One robot: its protocol state, its inventory, and the ROS goals it sends."""

    def __init__(self, link: RobotLink, workcell: WorkcellDescription, step_timeout_s: float = 600.0) -> None:
        self.link = link
        self.workcell = workcell
        self.step_timeout_s = step_timeout_s
        self.sequence = ManipulatorSequence()
        self.inventory = Inventory()
        self._active_goal: ActionGoal | None = None
        self._active_token: CancelToken | None = None  # the cancel token of the command that sent it
        self._active_lock = threading.Lock()
        self._sub_positions = {station.name: station.sub_positions for station in workcell.stations}
        link.on_robot_status(self.inventory.observe_robot)
        self.inventory.observe_robot(link.robot_status())

    # --- what the robot offers ---

    def handover_positions(self) -> list[tuple[str, int]]:
        """(station name, number of sub-positions) for every station the robot serves."""
        return [(station.name, station.sub_positions) for station in self.workcell.stations]

    @property
    def internal_positions(self) -> int:
        return self.workcell.hotel_slots

    # --- the standard's commands ---

    def prepare_for_input(
        self,
        position: str,
        sub_position: int,
        internal_position: int,
        labware_type: str,
        labware_id: str,
        report: ProgressReport | None = None,
    ) -> None:
        """Robot will receive a plate from `position`: the hotel slot must be free; drive there."""
        handover = check_handover(position, sub_position, self._sub_positions)
        check_internal_position(internal_position, self.internal_positions)
        check_text(labware_type, "LabwareType", allow_empty=True)
        check_text(labware_id, "LabwareUniqueID", allow_empty=True)
        occupant = self._hotel_occupant(self.link.robot_status(), internal_position)
        if occupant is not None:
            raise CommandSequenceError(
                f"PrepareForInput refused: internal position {internal_position} already holds "
                f"labware {occupant!r}"
            )
        transfer = PreparedTransfer(handover, internal_position, labware_type, labware_id)
        self.sequence.begin_prepare_for_input(transfer)
        self._drive_for_transfer(handover, report)

    def prepare_for_output(
        self, position: str, sub_position: int, internal_position: int, report: ProgressReport | None = None
    ) -> None:
        """Robot will hand a plate to `position`: the hotel slot must hold one; drive there."""
        handover = check_handover(position, sub_position, self._sub_positions)
        check_internal_position(internal_position, self.internal_positions)
        occupant = self._hotel_occupant(self.link.robot_status(), internal_position)
        if occupant is None:
            raise CommandSequenceError(
                f"PrepareForOutput refused: internal position {internal_position} holds no labware"
            )
        self._refuse_occupied_destination(handover)
        known = self.inventory.locate(occupant)
        transfer = PreparedTransfer(
            handover, internal_position, known.labware_type if known else "", occupant
        )
        self.sequence.begin_prepare_for_output(transfer)
        self._drive_for_transfer(handover, report)

    def get_labware(
        self,
        position: str,
        sub_position: int,
        intermediate_actions: list[str],
        report: ProgressReport | None = None,
    ) -> str:
        """Take the plate from the prepared station into the prepared hotel slot; returns its id."""
        return self._transfer("GetLabware", position, sub_position, intermediate_actions, report)

    def put_labware(
        self,
        position: str,
        sub_position: int,
        intermediate_actions: list[str],
        report: ProgressReport | None = None,
    ) -> str:
        """Place the plate of the prepared hotel slot into the prepared station nest; returns its id."""
        return self._transfer("PutLabware", position, sub_position, intermediate_actions, report)

    def _transfer(
        self,
        command: str,
        position: str,
        sub_position: int,
        intermediate_actions: list[str],
        report: ProgressReport | None,
    ) -> str:
        """GetLabware or PutLabware: check, match the prepared transfer, run the goal, settle the
        inventory from what the robot observed, then raise TransferFailed if the goal failed."""
        getting = command == "GetLabware"
        handover = check_handover(position, sub_position, self._sub_positions)
        check_intermediate_actions(intermediate_actions, INTERMEDIATE_ACTIONS)
        transfer = self.sequence.begin_get(handover) if getting else self.sequence.begin_put(handover)
        try:
            request = LabwareHandover(
                handover.station,
                handover.sub_position,
                transfer.internal_position,
                transfer.labware_type,
                transfer.labware_id,
                intermediate_actions,
            )
            send = self.link.get_labware if getting else self.link.put_labware
            outcome = self._wait(lambda: send(request, _ScaledReport(report, 0.0, 1.0)), command)
            labware_id = transfer.labware_id or str(getattr(outcome.result, "labware_id", ""))
            self._settle(labware_id, transfer, outcome, expect_aboard=getting)
            if not outcome.success:
                raise TransferFailed(outcome.error_code, _describe_failure(command, outcome))
            return labware_id
        finally:
            self.sequence.finish_transfer()

    # --- base motions outside the standard ---

    def dock(self, report: ProgressReport | None = None) -> None:
        self._motion("Dock", lambda: self.link.dock(_ScaledReport(report, 0.0, 1.0)))
        self._await_state_report(lambda status: status.docked, "docked")

    def undock(self, report: ProgressReport | None = None) -> None:
        self._motion("Undock", lambda: self.link.undock(_ScaledReport(report, 0.0, 1.0)))
        self._await_state_report(lambda status: not status.docked, "undocked")

    def drive_to_poi(self, poi: str, report: ProgressReport | None = None) -> None:
        check_text(poi, "PointOfInterest", allow_empty=False)
        if poi not in self.workcell.pois:
            raise MotionFailed(
                "UNKNOWN_POI", f"no point of interest {poi!r}; known: {', '.join(self.workcell.pois)}"
            )
        if self.link.robot_status().docked:
            raise MotionFailed("DOCKED", f"the robot is docked; undock before driving to {poi!r}")
        self._motion(
            "DriveToPointOfInterest", lambda: self.link.navigate_to_poi(poi, _ScaledReport(report, 0, 1))
        )
        self._await_arrival_report(poi)

    def stop_motion(self) -> bool:
        """Cancel whatever goal runs; True if one was running."""
        with self._active_lock:
            goal = self._active_goal
        if goal is None or goal.outcome.done():
            return False
        goal.cancel()
        return True

    def cancel_command(self, token: CancelToken, reason: str) -> bool:
        """Cancel the command running under `token` (see `cancellation`): its running goal now, and
        any goal it would send next. True if one of its goals was running."""
        token.cancel(reason)
        with self._active_lock:
            goal = self._active_goal if self._active_token is token else None
        if goal is None or goal.outcome.done():
            return False
        goal.cancel()
        return True

    def abort_active_goal(self, reason: str) -> bool:
        """End the waiting command now with a failed outcome (the robot side is gone and will not
        answer); True if one was waiting. The command then settles the inventory and raises its
        defined error as for any failed goal."""
        with self._active_lock:
            goal = self._active_goal
        if goal is None or goal.outcome.done():
            return False
        goal._finish_with_error(BridgeError(reason))
        return True

    # --- helpers ---

    def _motion(self, command: str, send: Callable[[], ActionGoal]) -> None:
        self.sequence.begin_motion(command)
        try:
            outcome = self._wait(send, command)
            if not outcome.success:
                raise MotionFailed(outcome.error_code, _describe_failure(command, outcome))
        finally:
            self.sequence.finish_motion()

    def _await_arrival_report(self, poi: str) -> None:
        self._await_state_report(lambda status: status.current_poi == poi, f"at {poi}")

    def _await_state_report(
        self, shows: Callable[[RobotStatus], bool], what: str, timeout_s: float = 2.0
    ) -> None:
        """After a base motion succeeded, wait until /robot_state shows its effect, so that the
        command ends with the state properties (and the next command's checks) already true: the
        state topic lags action results."""
        try:
            self.link.wait_for_robot_status(shows, timeout_s)
        except BridgeTimeout:
            logger.warning("the motion succeeded but the robot state does not report %s yet", what)

    def _drive_for_transfer(self, handover: Handover, report: ProgressReport | None) -> None:
        """Undock if needed, then drive to the station's POI (unless already there)."""
        success = False
        try:
            station = self.workcell.station(handover.station)
            assert station is not None  # check_handover passed
            status = self.link.robot_status()
            start = 0.0
            if status.docked:
                outcome = self._wait(lambda: self.link.undock(_ScaledReport(report, 0.0, 0.2)), "Undock")
                if not outcome.success:
                    raise MotionFailed(outcome.error_code, _describe_failure("Undock", outcome))
                start = 0.2
            if status.current_poi != station.poi or status.docked:
                outcome = self._wait(
                    lambda: self.link.navigate_to_poi(station.poi, _ScaledReport(report, start, 1.0)),
                    "NavigateToPoi",
                )
                if not outcome.success:
                    raise MotionFailed(
                        outcome.error_code, _describe_failure(f"driving to {station.poi}", outcome)
                    )
                self._await_arrival_report(station.poi)
            if report is not None:
                report(1.0, 0.0)
            success = True
        finally:
            self.sequence.finish_prepare(success)

    def _wait(self, send: Callable[[], ActionGoal], what: str) -> ActionOutcome:
        """Send the goal and return its outcome; bridge trouble (no answer, rejection, timeout, even
        while sending) becomes a failed outcome, so that callers always settle the inventory and
        raise their own defined error."""
        token = current_token()
        if token is not None and token.cancelled:
            return ActionOutcome(False, "CANCELED", f"{token.reason}; {what} was not started", "CANCELED")
        try:
            goal = send()
        except BridgeError as error:
            return ActionOutcome(False, type(error).__name__, f"{what} could not be sent: {error}", "")
        with self._active_lock:
            self._active_goal, self._active_token = goal, token
        try:
            if token is not None and token.cancelled:  # cancelled while the goal was being sent
                goal.cancel()
            goal.wait_accepted(timeout_s=30.0)
            try:
                outcome = goal.result(self.step_timeout_s)
                if token is not None and token.cancelled and not outcome.success:
                    outcome = dataclasses.replace(outcome, message=f"{token.reason}; {outcome.message}")
                return outcome
            except BridgeTimeout:
                logger.warning("%s took longer than %.0f s: cancelling it", what, self.step_timeout_s)
                goal.cancel()
                try:
                    return goal.result(10.0)
                except BridgeTimeout:
                    return ActionOutcome(
                        False, "TIMEOUT", f"{what}: no result within {self.step_timeout_s:.0f} s", ""
                    )
        except BridgeError as error:
            return ActionOutcome(False, type(error).__name__, str(error), "")
        finally:
            with self._active_lock:
                self._active_goal, self._active_token = None, None

    def _settle(
        self, labware_id: str, transfer: PreparedTransfer, outcome: ActionOutcome, expect_aboard: bool
    ) -> None:
        """Record where the plate really is, after the robot side reported the outcome."""
        if not labware_id:
            logger.warning("transfer at %s without a labware id: inventory not updated", transfer.handover)
            return
        expected_slot = in_hotel(transfer.internal_position)

        def shows_outcome(status: RobotStatus) -> bool:
            aboard = labware_id in status.onboard_labware_ids
            return aboard == expect_aboard if outcome.success else True

        try:
            status = self.link.wait_for_robot_status(shows_outcome, timeout_s=3.0)
        except BridgeTimeout:
            status = self.link.robot_status()
        if outcome.success and not expect_aboard:
            # /station_states comes at 2 Hz, /robot_state on change: without this wait a plate that
            # was placed could be read as in neither place, and recorded as lost (seen in the soak).
            try:
                self.link.wait_for_nest(transfer.handover.station, transfer.handover.sub_position, True, 3.0)
            except BridgeTimeout:
                logger.warning("PutLabware succeeded but the sensor of %s sees no plate", transfer.handover)
        location = self.inventory.settle(
            labware_id, transfer.labware_type, transfer.handover, status, self.link.nest_occupancies()
        )
        if outcome.success and expect_aboard and location != expected_slot:
            logger.warning(
                "GetLabware succeeded but %s is at %s, not %s", labware_id, location, expected_slot
            )

    def _refuse_occupied_destination(self, handover: Handover) -> None:
        """Before any motion: a nest whose sensor sees a plate cannot take another one."""
        for nest in self.link.nest_occupancies():
            here = (nest.station, nest.sub_position) == (handover.station, handover.sub_position)
            if here and nest.occupied:
                holder = f" (holds {nest.labware_id})" if nest.labware_id else ""
                raise CommandSequenceError(
                    f"PrepareForOutput refused: destination {handover.station}/{handover.sub_position} "
                    f"is occupied{holder}; the robot did not move"
                )

    @staticmethod
    def _hotel_occupant(status: RobotStatus, slot: int) -> str | None:
        for content in status.hotel:
            if content.index == slot and content.labware_id:
                return content.labware_id
        return None


def _describe_failure(what: str, outcome: ActionOutcome) -> str:
    reason = outcome.message or "no reason given"
    return f"{what} failed ({outcome.error_code}): {reason}"


__all__ = [
    "INTERMEDIATE_ACTIONS",
    "CommandSequenceError",
    "MotionFailed",
    "ParameterError",
    "ProgressReport",
    "RobotController",
    "TransferFailed",
]
