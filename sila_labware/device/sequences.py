"""The labware transfer protocol's command order, as two small state machines.

Protocol (SiLA labware transfer v1.0): the source device gets PrepareForOutput, the destination
PrepareForInput; then the active device (the robot) does GetLabware when it is the destination
or PutLabware when it is the source; then the passive device hears LabwareRemoved (it was the
source) or LabwareDelivered (it was the destination). Anything else raises
CommandSequenceError, which the SiLA layer reports as InvalidCommandSequence.

`ManipulatorSequence` (the robot) has one transfer at a time, with "busy" phases while a
Prepare (driving) or a Get/Put (arm motion) runs: a command arriving meanwhile is refused.
A failed step returns to idle, so a scheduler can prepare again. A motion command outside the
protocol (Dock, Undock, DriveToPointOfInterest) voids a pending preparation (`abandon`).

`SiteSequence` (a station, the passive device) keeps one state per nest. Prepare steps are
instant for this digital twin; occupancy comes from the station's sensor and is passed in.

Both are thread-safe (one lock each): SiLA handler threads call them concurrently.
"""

from __future__ import annotations

import enum
import threading
from dataclasses import dataclass

from labware_model.holders import Nest
from sila_labware.device.errors import CommandSequenceError


class ManipulatorPhase(enum.Enum):
    IDLE = "idle"
    PREPARING_INPUT = "preparing for input"
    PREPARED_FOR_INPUT = "prepared for input"
    PREPARING_OUTPUT = "preparing for output"
    PREPARED_FOR_OUTPUT = "prepared for output"
    GETTING = "getting labware"
    PUTTING = "putting labware"
    MOVING = "moving"


@dataclass(frozen=True)
class PreparedTransfer:
    """What a Prepare command announced: the hand-over nest, which hotel slot, which plate."""

    handover: Nest
    internal_position: int
    labware_type: str = ""
    labware_id: str = ""


_BUSY_PHASES = {
    ManipulatorPhase.PREPARING_INPUT,
    ManipulatorPhase.PREPARING_OUTPUT,
    ManipulatorPhase.GETTING,
    ManipulatorPhase.PUTTING,
    ManipulatorPhase.MOVING,
}


class ManipulatorSequence:
    """Command order of the active device (the robot)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._phase = ManipulatorPhase.IDLE
        self._transfer: PreparedTransfer | None = None

    @property
    def phase(self) -> ManipulatorPhase:
        with self._lock:
            return self._phase

    @property
    def transfer(self) -> PreparedTransfer | None:
        with self._lock:
            return self._transfer

    def begin_prepare_for_input(self, transfer: PreparedTransfer) -> None:
        self._begin_prepare(transfer, ManipulatorPhase.PREPARING_INPUT, "PrepareForInput")

    def begin_prepare_for_output(self, transfer: PreparedTransfer) -> None:
        self._begin_prepare(transfer, ManipulatorPhase.PREPARING_OUTPUT, "PrepareForOutput")

    def finish_prepare(self, success: bool) -> None:
        """End a running Prepare: prepared on success, idle on failure."""
        with self._lock:
            if self._phase is ManipulatorPhase.PREPARING_INPUT and success:
                self._phase = ManipulatorPhase.PREPARED_FOR_INPUT
            elif self._phase is ManipulatorPhase.PREPARING_OUTPUT and success:
                self._phase = ManipulatorPhase.PREPARED_FOR_OUTPUT
            elif self._phase in (ManipulatorPhase.PREPARING_INPUT, ManipulatorPhase.PREPARING_OUTPUT):
                self._phase, self._transfer = ManipulatorPhase.IDLE, None
            else:
                raise RuntimeError(f"finish_prepare while {self._phase.value}")

    def begin_get(self, handover: Nest) -> PreparedTransfer:
        """GetLabware is allowed only right after PrepareForInput at the same hand-over position."""
        return self._begin_transfer(
            handover, ManipulatorPhase.PREPARED_FOR_INPUT, ManipulatorPhase.GETTING, "GetLabware"
        )

    def begin_put(self, handover: Nest) -> PreparedTransfer:
        """PutLabware is allowed only right after PrepareForOutput at the same hand-over position."""
        return self._begin_transfer(
            handover, ManipulatorPhase.PREPARED_FOR_OUTPUT, ManipulatorPhase.PUTTING, "PutLabware"
        )

    def finish_transfer(self) -> None:
        """End a Get/Put, successful or not: the robot is idle again and must be prepared anew."""
        with self._lock:
            if self._phase not in (ManipulatorPhase.GETTING, ManipulatorPhase.PUTTING):
                raise RuntimeError(f"finish_transfer while {self._phase.value}")
            self._phase, self._transfer = ManipulatorPhase.IDLE, None

    def begin_motion(self, command: str) -> None:
        """A motion outside the protocol (dock, drive): refused while busy; voids a preparation."""
        with self._lock:
            self._refuse_if_busy(command)
            self._phase, self._transfer = ManipulatorPhase.MOVING, None

    def finish_motion(self) -> None:
        with self._lock:
            if self._phase is ManipulatorPhase.MOVING:
                self._phase = ManipulatorPhase.IDLE

    def _refuse_if_busy(self, command: str) -> None:
        if self._phase in _BUSY_PHASES:
            where = f" at {self._transfer.handover}" if self._transfer else ""
            raise CommandSequenceError(f"{command} refused: the robot is busy {self._phase.value}{where}")

    def _begin_prepare(self, transfer: PreparedTransfer, busy: ManipulatorPhase, command: str) -> None:
        with self._lock:
            self._refuse_if_busy(command)
            if self._phase is not ManipulatorPhase.IDLE:
                assert self._transfer is not None
                follow_up = (
                    "GetLabware" if self._phase is ManipulatorPhase.PREPARED_FOR_INPUT else "PutLabware"
                )
                raise CommandSequenceError(
                    f"{command} refused: the robot is already {self._phase.value} "
                    f"at {self._transfer.handover}; "
                    f"send {follow_up} for that hand-over position first"
                )
            self._phase, self._transfer = busy, transfer

    def _begin_transfer(
        self, handover: Nest, required: ManipulatorPhase, busy: ManipulatorPhase, command: str
    ) -> PreparedTransfer:
        with self._lock:
            self._refuse_if_busy(command)
            prepare = (
                "PrepareForInput" if required is ManipulatorPhase.PREPARED_FOR_INPUT else "PrepareForOutput"
            )
            if self._phase is not required:
                now = (
                    "idle" if self._transfer is None else f"{self._phase.value} at {self._transfer.handover}"
                )
                raise CommandSequenceError(f"{command} needs {prepare} first; the robot is {now}")
            assert self._transfer is not None
            if self._transfer.handover != handover:
                raise CommandSequenceError(
                    f"{command} at {handover}, but {prepare} was for {self._transfer.handover}"
                )
            self._phase = busy
            return self._transfer


class NestPhase(enum.Enum):
    IDLE = "idle"
    PREPARED_FOR_INPUT = "prepared for input"
    PREPARED_FOR_OUTPUT = "prepared for output"


@dataclass(frozen=True)
class NestExpectation:
    """What a prepared nest waits for."""

    phase: NestPhase
    internal_position: int = 1
    labware_type: str = ""
    labware_id: str = ""


class SiteSequence:
    """Command order of a passive device (a station), one state per nest (sub-position)."""

    def __init__(self, station: str, sub_positions: int) -> None:
        self.station = station
        self._lock = threading.Lock()
        self._nests = {index: NestExpectation(NestPhase.IDLE) for index in range(1, sub_positions + 1)}

    def reset(self) -> None:
        """Every nest idle, nothing announced (after a lab reset)."""
        with self._lock:
            self._nests = {index: NestExpectation(NestPhase.IDLE) for index in self._nests}

    def nest(self, sub_position: int) -> NestExpectation:
        with self._lock:
            return self._nests[sub_position]

    def prepare_for_input(
        self, sub_position: int, internal_position: int, labware_type: str, labware_id: str, occupied: bool
    ) -> None:
        """The station will receive a plate: refused while the nest is occupied or already prepared."""
        with self._lock:
            self._refuse_unless_idle(sub_position, "PrepareForInput")
            if occupied:
                raise CommandSequenceError(
                    f"PrepareForInput refused: nest {Nest(self.station, sub_position)} is occupied; "
                    "the plate there must be removed first"
                )
            self._nests[sub_position] = NestExpectation(
                NestPhase.PREPARED_FOR_INPUT, internal_position, labware_type, labware_id
            )

    def prepare_for_output(self, sub_position: int, internal_position: int, occupied: bool) -> None:
        """The station will hand a plate over: refused while the nest is empty or already prepared."""
        with self._lock:
            self._refuse_unless_idle(sub_position, "PrepareForOutput")
            if not occupied:
                raise CommandSequenceError(
                    f"PrepareForOutput refused: nest {Nest(self.station, sub_position)} is empty; "
                    "nothing to hand over"
                )
            self._nests[sub_position] = NestExpectation(NestPhase.PREPARED_FOR_OUTPUT, internal_position)

    def labware_delivered(self, sub_position: int) -> NestExpectation:
        """Only after PrepareForInput; returns what was announced and makes the nest idle."""
        return self._complete(
            sub_position, NestPhase.PREPARED_FOR_INPUT, "LabwareDelivered", "PrepareForInput"
        )

    def labware_removed(self, sub_position: int) -> NestExpectation:
        """Only after PrepareForOutput; makes the nest idle."""
        return self._complete(
            sub_position, NestPhase.PREPARED_FOR_OUTPUT, "LabwareRemoved", "PrepareForOutput"
        )

    def _refuse_unless_idle(self, sub_position: int, command: str) -> None:
        current = self._nests[sub_position].phase
        if current is not NestPhase.IDLE:
            follow_up = "LabwareDelivered" if current is NestPhase.PREPARED_FOR_INPUT else "LabwareRemoved"
            raise CommandSequenceError(
                f"{command} refused: nest {Nest(self.station, sub_position)} is already {current.value}; "
                f"{follow_up} must come first"
            )

    def _complete(
        self, sub_position: int, required: NestPhase, command: str, prepare: str
    ) -> NestExpectation:
        with self._lock:
            expectation = self._nests[sub_position]
            if expectation.phase is not required:
                raise CommandSequenceError(
                    f"{command} at {Nest(self.station, sub_position)} needs {prepare} first; "
                    f"the nest is {expectation.phase.value}"
                )
            self._nests[sub_position] = NestExpectation(NestPhase.IDLE)
            return expectation
