"""The robot's behaviour behind its SiLA features: protocol order, checks, ROS goals, inventory.

This is the front-end logic of the active device; below it is a `RobotBackend` (robot_backend.py):
the ROS bridge's `RobotLink` in a deployment, so a real TIAGo++ serving the same ROS names changes
nothing here, or an in-memory fake in the fast tests. It never imports sila2: the feature
implementations translate its exceptions into SiLA errors:

- `CommandSequenceError` -> InvalidCommandSequence (RobotBusy for motion commands)
- `ParameterError` -> a validation error naming the parameter
- `TransferFailed` -> LabwareNotPicked / LabwareNotPlaced, with the robot side's message; also
  when the robot side reported success but the presence sensor of the place the command put the
  plate sees none (PLATE_SLIPPED after GetLabware, PLACE_FAILED after PutLabware)
- `MotionFailed` -> the MobileRobotController error for its ROS error code

The inventory is the robot side's (labware_model.inventory), mirrored here (`inventory`): the
scheduler's LabwareUniqueID is the plate's name, which the robot side takes at the source of a
transfer; where a plate is follows the robot's presence sensors, never a label read off it.

Progress: each command reports through one `CommandProgress` (ros_bridge.progress), which maps
each of its goals into a share of the command (undock 0..0.2, then drive 0.2..1) and never lets
the reported fraction go down.

A command can be cancelled by its execution (`cancel_command` with the token it runs under, see
`cancellation`) or, whatever runs, by `stop_motion`; either ends it with its defined error.

Threads: methods run on SiLA handler threads and block until the goal ends, waiting on the goal's
status; progress reports are called on the back end's answering thread (the ROS thread) from goal
feedback, and on the handler thread at the end of a command. `stop_motion` and
`abort_active_goal` may be called from any other thread while a command waits.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from labware_model.holders import UNKNOWN, HotelSlot, Location, Nest, aboard, location_text
from labware_model.workcell import WorkcellDescription
from ros_bridge.errors import BridgeTimeout
from ros_bridge.goal_status import ActionGoal, ActionOutcome
from ros_bridge.progress import CommandProgress, ProgressReport
from ros_bridge.robot_pace import RobotPace
from ros_bridge.workcell import LabwareHandover, RobotStatus
from sila_labware.device.cancellation import CancelToken
from sila_labware.device.errors import CommandSequenceError, MotionFailed, TransferFailed
from sila_labware.device.goal_runner import ControllerWaits, GoalRunner
from sila_labware.device.inventory import Inventory
from sila_labware.device.robot_backend import RobotBackend
from sila_labware.device.sequences import ManipulatorSequence, PreparedTransfer
from sila_labware.device.validation import DeviceParameters

logger = logging.getLogger(__name__)

INTERMEDIATE_ACTIONS: tuple[str, ...] = ()
"""Fully qualified command identifiers this robot can run between pick and place: none yet."""


class RobotController:
    """One robot: its protocol state, its inventory, and the goals it sends to its back end."""

    def __init__(
        self,
        link: RobotBackend,
        workcell: WorkcellDescription,
        step_timeout_s: float = 600.0,
        waits: ControllerWaits | None = None,
    ) -> None:
        self.link = link
        self.workcell = workcell
        self.step_timeout_s = step_timeout_s
        self.waits = waits or ControllerWaits()
        self.sequence = ManipulatorSequence()
        self.inventory = Inventory()
        self.goals = GoalRunner(link, step_timeout_s, self.waits)
        self.parameters = DeviceParameters(
            {station.name: station.sub_positions for station in workcell.stations},
            workcell.hotel_slots,
            workcell.pois,
            INTERMEDIATE_ACTIONS,
        )
        self.pace = RobotPace()  # remaining times are reported in wall seconds at the robot's pace
        link.on_inventory(self.inventory.replace)
        link.on_robot_status(self.pace.observe)
        try:
            self.inventory.replace(link.inventory(timeout_s=0.0))
        except BridgeTimeout:
            pass  # none published yet: the listener takes the first one

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
        handover = self.parameters.prepare(
            position, sub_position, internal_position, labware_type, labware_id
        )
        self._refuse_a_name_in_use(labware_id, handover)
        occupant = self._hotel_occupant(self.link.robot_status(), internal_position)
        if occupant is not None:
            what = f"labware {occupant!r}" if occupant else "a plate nobody has named"
            raise CommandSequenceError(
                f"PrepareForInput refused: internal position {internal_position} already holds {what}"
            )
        transfer = PreparedTransfer(handover, internal_position, labware_type, labware_id)
        self.sequence.begin_prepare_for_input(transfer)
        self._drive_for_transfer(handover, CommandProgress(report, self.pace.to_wall_s))

    def prepare_for_output(
        self, position: str, sub_position: int, internal_position: int, report: ProgressReport | None = None
    ) -> None:
        """Robot will hand a plate to `position`: the hotel slot must hold one; drive there."""
        handover = self.parameters.prepare(position, sub_position, internal_position)
        occupant = self._hotel_occupant(self.link.robot_status(), internal_position)
        if occupant is None:
            raise CommandSequenceError(
                f"PrepareForOutput refused: internal position {internal_position} holds no labware"
            )
        self._refuse_occupied_destination(handover)
        known = self.inventory.locate(occupant) if occupant else None
        transfer = PreparedTransfer(
            handover, internal_position, known.labware_type if known else "", occupant
        )
        self.sequence.begin_prepare_for_output(transfer)
        self._drive_for_transfer(handover, CommandProgress(report, self.pace.to_wall_s))

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
        inventory from what the robot observed, then raise TransferFailed if the goal failed or
        the sensors do not show its effect."""
        getting = command == "GetLabware"
        handover = self.parameters.transfer(position, sub_position, intermediate_actions)
        transfer = self.sequence.begin_get(handover) if getting else self.sequence.begin_put(handover)
        try:
            request = LabwareHandover(
                handover,
                HotelSlot(transfer.internal_position),
                transfer.labware_type,
                transfer.labware_id,
                intermediate_actions,
            )
            send = self.link.get_labware if getting else self.link.put_labware
            progress = CommandProgress(report, self.pace.to_wall_s)
            outcome = self.goals.run(lambda: send(request, progress.step(0.0, 1.0)), command)
            labware_id = str(getattr(outcome.result, "labware_id", "")) or transfer.labware_id
            self._settle(labware_id, transfer, outcome)
            if not outcome.success:
                raise TransferFailed(outcome.error_code, _describe_failure(command, outcome))
            self._refuse_unseen_effect(command, labware_id, transfer)
            return labware_id
        finally:
            self.sequence.finish_transfer()

    # --- base motions outside the standard ---

    def dock(self, report: ProgressReport | None = None) -> None:
        progress = CommandProgress(report, self.pace.to_wall_s)
        self._motion("Dock", lambda: self.link.dock(progress.step(0.0, 1.0)))
        self.goals.await_state(lambda status: status.docked, "docked", progress)

    def undock(self, report: ProgressReport | None = None) -> None:
        progress = CommandProgress(report, self.pace.to_wall_s)
        self._motion("Undock", lambda: self.link.undock(progress.step(0.0, 1.0)))
        self.goals.await_state(lambda status: status.state == RobotStatus.IDLE, "idle off the dock", progress)

    def drive_to_poi(self, poi: str, report: ProgressReport | None = None) -> None:
        self.parameters.point_of_interest(poi)
        if self.link.robot_status().docked:
            raise MotionFailed("DOCKED", f"the robot is docked; undock before driving to {poi!r}")
        progress = CommandProgress(report, self.pace.to_wall_s)
        self._motion(
            "DriveToPointOfInterest", lambda: self.link.navigate_to_poi(poi, progress.step(0.0, 1.0))
        )
        self._await_arrival_report(poi, progress)

    def stop_motion(self) -> bool:
        """Cancel whatever goal runs; returns once the robot stands (see GoalRunner.stop)."""
        return self.goals.stop()

    def cancel_command(self, token: CancelToken, reason: str) -> bool:
        """Cancel the command running under `token` (see `cancellation`): its running goal now, and
        any goal it would send next. True if one of its goals was running."""
        return self.goals.cancel(token, reason)

    def abort_active_goal(self, reason: str) -> bool:
        """End the waiting command now (the robot side is gone and will not answer): its goal ends
        with GoalAbandoned(`reason`); True if a goal was still running. The command then settles
        the inventory and raises its defined error as for any failed goal. Any thread."""
        return self.goals.abort(reason)

    # --- helpers ---

    def _motion(self, command: str, send: Callable[[], ActionGoal]) -> None:
        self.sequence.begin_motion(command)
        try:
            outcome = self.goals.run(send, command)
            if not outcome.success:
                raise MotionFailed(outcome.error_code, _describe_failure(command, outcome))
        finally:
            self.sequence.finish_motion()

    def _await_arrival_report(self, poi: str, progress: CommandProgress) -> None:
        self.goals.await_state(
            lambda status: status.current_poi == poi and status.state == RobotStatus.IDLE,
            f"idle at {poi}",
            progress,
        )

    def _drive_for_transfer(self, handover: Nest, progress: CommandProgress) -> None:
        """Undock if needed, then drive to the station's POI (unless already there)."""
        success = False
        try:
            station = self.workcell.station(handover.station)
            assert station is not None  # check_handover passed
            status = self.link.robot_status()
            start = 0.0
            if status.docked:
                # the undock's remaining time counts the drive after it (the robot side plans it)
                undocking = progress.step(0.0, 0.2, last=False, counts_rest=True)
                outcome = self.goals.run(lambda: self.link.undock(undocking, then_poi=station.poi), "Undock")
                if not outcome.success:
                    raise MotionFailed(outcome.error_code, _describe_failure("Undock", outcome))
                start = 0.2
            if status.current_poi != station.poi or status.docked:
                outcome = self.goals.run(
                    lambda: self.link.navigate_to_poi(station.poi, progress.step(start, 1.0)),
                    "NavigateToPoi",
                )
                if not outcome.success:
                    raise MotionFailed(
                        outcome.error_code, _describe_failure(f"driving to {station.poi}", outcome)
                    )
                self._await_arrival_report(station.poi, progress)
            progress.finish()
            success = True
        finally:
            self.sequence.finish_prepare(success)

    def _settle(self, labware_id: str, transfer: PreparedTransfer, outcome: ActionOutcome) -> None:
        """Bring the mirror up to the robot side's inventory as the goal left it (the result carries
        that revision; an older robot side that sends none is waited for one report)."""
        if not labware_id:
            logger.warning("transfer at %s without a labware id: nobody named the plate", transfer.handover)
        revision = int(getattr(outcome.result, "inventory_revision", 0) or 0)
        try:
            snapshot = self.link.wait_for_inventory(
                lambda snapshot: snapshot.revision >= revision, self.waits.settle_s
            )
        except BridgeTimeout:
            logger.warning("no /labware_inventory of revision %d within %g s", revision, self.waits.settle_s)
            return
        self.inventory.replace(snapshot)

    def _refuse_unseen_effect(self, command: str, labware_id: str, transfer: PreparedTransfer) -> None:
        """A transfer the robot side reported done must show in the presence sensor of the place it
        put the plate: its hotel slot after GetLabware, its nest after PutLabware; else TransferFailed.
        Presence only: a label that reads other than the plate's name is a note, not a slip."""
        getting = command == "GetLabware"
        expected: Location = HotelSlot(transfer.internal_position) if getting else transfer.handover
        sensors = self.workcell.sensors
        if not (sensors.hotel if getting else sensors.nests):
            # No presence sensor there: the robot side checked the place otherwise (the fingers'
            # gap in the pocket, the head camera in the nest) and settled its inventory on it.
            record = self.inventory.at(expected)
            if record is not None and (not labware_id or record.labware_id == labware_id):
                return
            code = "PLATE_SLIPPED" if getting else "PLACE_FAILED"
            raise TransferFailed(
                code,
                f"{command} failed ({code}): the robot side reported success, but its inventory has no "
                f"plate at {expected}",
            )
        try:
            if getting:
                self.link.wait_for_robot_status(
                    lambda status: self._hotel_occupant(status, transfer.internal_position) is not None,
                    self.waits.settle_s,
                )
            else:
                self.link.wait_for_nest(transfer.handover, True, self.waits.settle_s)
            return
        except BridgeTimeout:
            pass
        record = self.inventory.locate(labware_id) if labware_id else None
        where = (
            ""
            if record is None or record.location == UNKNOWN
            else f"; the inventory has it at {location_text(record.location)}"
        )
        code = "PLATE_SLIPPED" if getting else "PLACE_FAILED"
        raise TransferFailed(
            code,
            f"{command} failed ({code}): the robot side reported success, but the sensor of "
            f"{expected} sees no plate{where}",
        )

    def _refuse_a_name_in_use(self, labware_id: str, handover: Nest) -> None:
        """PrepareForInput names the plate at `handover`: no other plate may carry that name."""
        record = self.inventory.locate(labware_id) if labware_id else None
        if record is None or record.location in (handover, UNKNOWN):
            return
        where = "already aboard" if aboard(record.location) else f"at {record.location}"
        raise CommandSequenceError(
            f"PrepareForInput refused: labware {labware_id!r} is {where}, not at {handover}; "
            "a labware id names one plate"
        )

    def _refuse_occupied_destination(self, handover: Nest) -> None:
        """Before any motion: a nest whose sensor sees a plate cannot take another one; where the
        nests have no sensors, one the inventory places a plate in (the robot's head camera then
        looks before it places)."""
        if not self.workcell.sensors.nests:
            record = self.inventory.at(handover)
            if record is not None:
                raise CommandSequenceError(
                    f"PrepareForOutput refused: the inventory has {record.labware_id or 'a plate'} at "
                    f"destination {handover}; the robot did not move"
                )
            return
        for reading in self.link.nest_readings():
            if reading.nest == handover and reading.occupied:
                holder = f" (holds {reading.labware_id})" if reading.labware_id else ""
                raise CommandSequenceError(
                    f"PrepareForOutput refused: destination {handover} is occupied{holder}; "
                    "the robot did not move"
                )

    def _hotel_occupant(self, status: RobotStatus, slot: int) -> str | None:
        """The name of the plate in the hotel slot ("" for a plate nobody named); None when its
        presence sensor sees none, or, where the hotel has no sensors, the inventory records none."""
        if not self.workcell.sensors.hotel:
            record = self.inventory.in_hotel_slot(slot)
            return None if record is None else record.labware_id
        for reading in status.hotel:
            if reading.slot.index == slot and reading.occupied:
                record = self.inventory.in_hotel_slot(slot)
                return record.labware_id if record is not None else ""
        return None


def _describe_failure(what: str, outcome: ActionOutcome) -> str:
    reason = outcome.message or "no reason given"
    return f"{what} failed ({outcome.error_code}): {reason}"
