"""`LabwareTransferClient`: the robot and its stations as one object a scheduler can call.

Why: the standard transfer is six steps and eight commands across three servers, sent in an order
the standard fixes (SiLA labware transfer v1.0, see the README); every client used to write that
sequence out again. Here `transfer(source, destination)` sends it, `pick` and `place` send its two
halves (so a batch can stow plates in the robot's internal positions and deliver them later), and
the robot's own features (MobileRobotController, LabwareInventory) get one method each. Every
failure raises a typed exception (`sila_labware.client.errors`); no method returns False or None
to say it failed.

Only sila2's client is used: this works against any `sila-labware serve`, or any robot and
stations serving the standard features, from any machine that reaches them.

After a failure the client does not repair anything: the exception's `step` says where the
sequence stopped, `locate` and `onboard_labware` say where the plate is. When only one of a
step's two Prepare commands is refused, the other device stays prepared, as the standard has no
command to withdraw a preparation: the robot drops it at its next motion command (`drive_to`,
`dock`), a station keeps it until the matching LabwareRemoved or LabwareDelivered.

Threads: call one method at a time from one thread (the robot refuses a second motion anyway);
`stop()` may be called from any thread, e.g. a stop button's. `on_progress` callbacks run on the
calling thread.
"""

from __future__ import annotations

import logging
import operator
from collections.abc import Callable, Sequence
from types import TracebackType
from typing import Any, TypeVar

from sila2.client import SilaClient
from sila2.framework import SilaConnectionError

from labware_model.holders import Nest
from sila_labware.client import feature_modules
from sila_labware.client.bounded import CALL_TIMEOUT_S, bounded
from sila_labware.client.errors import LabwareTransferError, ParameterRejected, ServerUnreachable, translate
from sila_labware.client.records import Address, Handover, HandoverPosition, LabwareLocation, OnboardLabware
from sila_labware.client.sequence import StepPlan, pick_sequence, place_sequence
from sila_labware.client.steps import DEFAULT_STEP_TIMEOUT_S, Command, ProgressCallback, run_step

logger = logging.getLogger(__name__)

T = TypeVar("T")


def connect(address: Address, root_certs: bytes | None, insecure: bool) -> SilaClient:
    """A sila2 client of one server; ServerUnreachable if it does not answer (or refuses our TLS)."""
    feature_modules.enable()
    host, port = address
    try:
        if insecure:
            return bounded(lambda: SilaClient(host, port, insecure=True), CALL_TIMEOUT_S, f"{host}:{port}")
        return bounded(
            lambda: SilaClient(host, port, root_certs=root_certs), CALL_TIMEOUT_S, f"{host}:{port}"
        )
    except (SilaConnectionError, OSError) as error:
        raise ServerUnreachable(f"no SiLA server answers at {host}:{port}: {error}") from error


class LabwareTransferClient:
    """The standard labware transfer and the robot's own commands, each as one blocking call."""

    def __init__(
        self,
        robot: Address,
        stations: Sequence[Address],
        *,
        root_certs: bytes | None = None,
        insecure: bool = False,
        step_timeout_s: float = DEFAULT_STEP_TIMEOUT_S,
    ) -> None:
        """Connect to the robot's server and every station's; the station names come from the
        stations themselves (their handover positions).

        `root_certs` is the CA certificate (PEM bytes, `serve` writes it to sila-labware-ca.pem);
        `insecure=True` talks plain gRPC (tests only; the standard forbids it). With neither, the
        system's trusted CAs apply. Raises ServerUnreachable, or LabwareTransferError when a server
        lacks the feature its role needs.
        """
        if root_certs is not None and insecure:
            raise ValueError("give root_certs (TLS) or insecure=True, not both")
        if step_timeout_s <= 0:
            raise ValueError(f"step_timeout_s must be positive, not {step_timeout_s}")
        self.step_timeout_s = step_timeout_s
        self._clients: list[SilaClient] = []
        try:
            self._robot = self._open(robot, root_certs, insecure)
            self._manipulator = self._feature(self._robot, "LabwareTransferManipulatorController", robot)
            self._sites: dict[str, Any] = {}
            self._sub_positions: dict[str, int] = {}  # per station, as its server offers them
            for address in stations:
                site = self._feature(
                    self._open(address, root_certs, insecure), "LabwareTransferSiteController", address
                )
                for offered in self._call("AvailableHandoverPositions", site.AvailableHandoverPositions.get):
                    self._sites[offered.Position] = site
                    self._sub_positions[offered.Position] = int(offered.SubPosition)
        except BaseException:
            self.close()
            raise

    # --- the standard transfer ---

    def transfer(
        self,
        source: Handover,
        destination: Handover,
        *,
        labware_id: str = "",
        labware_type: str = "",
        internal_position: int = 1,
        on_progress: ProgressCallback | None = None,
    ) -> None:
        """Move a plate from `source` to `destination`: `pick`, then `place`, through the robot's
        `internal_position`. Both handovers are checked before anything moves."""
        self._site_of(source, "transfer")
        self._site_of(destination, "transfer")
        self.pick(
            source,
            internal_position=internal_position,
            labware_id=labware_id,
            labware_type=labware_type,
            on_progress=on_progress,
        )
        self.place(
            destination,
            internal_position=internal_position,
            labware_id=labware_id,
            labware_type=labware_type,
            on_progress=on_progress,
        )

    def pick(
        self,
        source: Handover,
        *,
        internal_position: int = 1,
        labware_id: str = "",
        labware_type: str = "",
        on_progress: ProgressCallback | None = None,
    ) -> None:
        """Take the plate at `source` into the robot's `internal_position`: the steps PICK_STEPS
        (source PrepareForOutput with robot PrepareForInput, robot GetLabware, source
        LabwareRemoved)."""
        handover, site = self._site_of(source, "pick")
        plan = pick_sequence(self._manipulator, site, handover, internal_position, labware_type, labware_id)
        self._run(plan, on_progress)

    def place(
        self,
        destination: Handover,
        *,
        internal_position: int = 1,
        labware_id: str = "",
        labware_type: str = "",
        on_progress: ProgressCallback | None = None,
    ) -> None:
        """Put the plate from the robot's `internal_position` into `destination`: the steps
        PLACE_STEPS (destination PrepareForInput with robot PrepareForOutput, robot PutLabware,
        destination LabwareDelivered). The destination is told the plate's id and type; when not
        given, what the robot reports carrying in that internal position."""
        handover, site = self._site_of(destination, "place")
        if not labware_id and self._optional_feature("MobileRobotController") is not None:
            carried = {item.internal_position: item for item in self.onboard_labware()}
            if internal_position in carried:
                labware_id = carried[internal_position].labware_id
                labware_type = labware_type or carried[internal_position].labware_type
        plan = place_sequence(self._manipulator, site, handover, internal_position, labware_type, labware_id)
        self._run(plan, on_progress)

    # --- the robot's own commands (MobileRobotController, LabwareInventory) ---

    def dock(self, *, on_progress: ProgressCallback | None = None) -> None:
        """Drive onto the charging dock (at once if docked). DockingFailed, RobotBusy, MotionStopped."""
        mobile = self._required_feature("MobileRobotController")
        self._step("Robot.Dock", [Command("Robot.Dock", mobile.Dock)], on_progress)

    def undock(self, *, on_progress: ProgressCallback | None = None) -> None:
        """Back off the dock (at once if not docked). UndockingFailed, RobotBusy, MotionStopped."""
        mobile = self._required_feature("MobileRobotController")
        self._step("Robot.Undock", [Command("Robot.Undock", mobile.Undock)], on_progress)

    def drive_to(self, poi: str, *, on_progress: ProgressCallback | None = None) -> None:
        """Drive the base to a point of interest (see `points_of_interest`); undock first.
        UnknownPointOfInterest, NavigationFailed, RobotDocked, RobotBusy, MotionStopped."""
        mobile = self._required_feature("MobileRobotController")
        command = "Robot.DriveToPointOfInterest"
        self._step(
            command,
            [Command(command, lambda: mobile.DriveToPointOfInterest(PointOfInterest=poi))],
            on_progress,
        )

    def stop(self) -> None:
        """Stop the base and arms now; a running motion ends with MotionStopped, a running
        transfer step with its defined error. Safe from any thread."""
        mobile = self._required_feature("MobileRobotController")
        self._call("Robot.StopMotion", mobile.StopMotion)

    def locate(self, labware_id: str) -> LabwareLocation:
        """Where the robot's inventory says the plate is. UnknownLabware if the robot never
        handled it or lost track of it after a failed transfer."""
        inventory = self._required_feature("LabwareInventory")
        found = self._call(
            "Robot.LocateLabware", lambda: inventory.LocateLabware(LabwareUniqueID=labware_id)
        ).Location
        return LabwareLocation.from_sila(
            found.LabwareUniqueID,
            found.LabwareType,
            found.Aboard,
            found.Position,
            found.Index,
            self.internal_positions(),
        )

    # --- what the robot and stations offer ---

    @property
    def stations(self) -> tuple[str, ...]:
        """The station names the connected station servers serve."""
        return tuple(self._sites)

    def handover_positions(self) -> list[HandoverPosition]:
        """Every station the robot serves, with its number of sub-positions."""
        offered = self._call(
            "Robot.AvailableHandoverPositions", self._manipulator.AvailableHandoverPositions.get
        )
        return [HandoverPosition(item.Position, item.SubPosition) for item in offered]

    def internal_positions(self) -> int:
        """How many plates the robot can carry at once (its hotel slots), numbered from 1."""
        return int(
            self._call("Robot.NumberOfInternalPositions", self._manipulator.NumberOfInternalPositions.get)
        )

    def points_of_interest(self) -> list[str]:
        """The names `drive_to` accepts."""
        mobile = self._required_feature("MobileRobotController")
        return list(self._call("Robot.PointsOfInterest", mobile.PointsOfInterest.get))

    def onboard_labware(self) -> list[OnboardLabware]:
        """The plates the robot carries, in internal-position order."""
        mobile = self._required_feature("MobileRobotController")
        items = self._call("Robot.OnboardLabware", mobile.OnboardLabware.get)
        return [
            OnboardLabware(item.InternalPosition, item.LabwareUniqueID, item.LabwareType) for item in items
        ]

    # --- connections ---

    def close(self) -> None:
        """Close every server connection; the client is unusable afterwards."""
        for client in self._clients:
            try:
                client.close()
            except Exception:  # noqa: BLE001 - closing the rest anyway
                logger.debug("closing a SiLA client raised", exc_info=True)
        self._clients.clear()

    def __enter__(self) -> LabwareTransferClient:
        return self

    def __exit__(
        self, _type: type[BaseException] | None, _error: BaseException | None, _tb: TracebackType | None
    ) -> None:
        self.close()

    # --- helpers ---

    def _open(self, address: Address, root_certs: bytes | None, insecure: bool) -> SilaClient:
        client = connect(address, root_certs, insecure)
        self._clients.append(client)
        return client

    @staticmethod
    def _feature(client: SilaClient, name: str, address: Address) -> Any:
        feature = getattr(client, name, None)
        if feature is None:
            raise LabwareTransferError(f"the server at {address[0]}:{address[1]} does not serve {name}")
        return feature

    def _optional_feature(self, name: str) -> Any | None:
        return getattr(self._robot, name, None)

    def _required_feature(self, name: str) -> Any:
        return self._feature(self._robot, name, (self._robot.address, self._robot.port))

    def _site_of(self, handover: Handover, command: str) -> tuple[tuple[str, int], Any]:
        """The checked handover and its station's site feature; ParameterRejected before anything
        is sent."""
        try:
            station, sub_position = (
                (handover.station, handover.sub_position) if isinstance(handover, Nest) else handover
            )
        except (TypeError, ValueError):
            raise ParameterRejected(
                f"a handover position is (station, sub-position), not {handover!r}",
                command=command,
                parameter="HandoverPosition",
            ) from None
        if station not in self._sites:
            known = ", ".join(self._sites) or "none"
            raise ParameterRejected(
                f"no connected station serves {station!r} (stations: {known})",
                command=command,
                parameter="HandoverPosition",
            )
        try:
            whole = operator.index(sub_position)  # ints and integer types such as numpy's, not 1.0
        except TypeError:
            whole = 0
        if whole < 1 or isinstance(sub_position, bool):
            raise ParameterRejected(
                f"sub-position {sub_position!r} of {station} is not a whole number from 1",
                command=command,
                parameter="HandoverPosition",
            )
        if whole > self._sub_positions[station]:
            raise ParameterRejected(
                f"{station} has sub-positions 1..{self._sub_positions[station]}, not {whole}",
                command=command,
                parameter="HandoverPosition",
            )
        return (station, whole), self._sites[station]

    def _run(self, plan: StepPlan, on_progress: ProgressCallback | None) -> None:
        for step, commands in plan:
            self._step(step, commands, on_progress)

    def _step(self, step: str, commands: list[Command], on_progress: ProgressCallback | None) -> None:
        run_step(
            step,
            commands,
            on_progress=on_progress,
            timeout_s=self.step_timeout_s,
            stop_devices=self._stop_after_abandoned_step,
        )

    def _stop_after_abandoned_step(self) -> None:
        """The client stops waiting (timeout, Ctrl-C): the robot must not go on by itself."""
        mobile = self._optional_feature("MobileRobotController")
        if mobile is None:
            return
        try:
            mobile.StopMotion()
        except Exception:  # noqa: BLE001 - the step's own error is the one to raise
            logger.warning("could not stop the robot after an abandoned step", exc_info=True)

    @staticmethod
    def _call(command: str, call: Callable[[], T]) -> T:
        """An unobservable command or property read, its errors typed, its wait bounded."""
        try:
            return bounded(call, CALL_TIMEOUT_S, command)
        except Exception as error:  # noqa: BLE001 - typed and re-raised
            typed = translate(error, command=command)
            if typed is error:
                raise
            raise typed from error
