"""The SiLA core features against the whole stack, with real sila2 clients over gRPC: CancelController
(robot), LockController and SimulationController (every server).

- Cancel: a generic client cancels a running drive, a running Prepare and a running GetLabware by its
  execution UUID; the command ends "finished with error" with a message naming the cancel, the robot
  comes to rest (its base pose, or its joints, stop changing), the inventory matches physics, and a
  complete transfer follows. Unknown and finished UUIDs are InvalidCommandExecutionUUID; CancelAll
  ends what runs and is a no-op otherwise.
- Lock: client A locks; client B's property reads and commands are refused (no token: the framework
  error InvalidMetadata; a wrong token: InvalidLockIdentifier), observable commands at initiation
  (no execution is created); A's calls with the token work; unlocking or the timeout frees B.
- Simulation: every server is in simulation mode and refuses real mode with StartRealModeFailed.

One stack for the module; the tests run in file order (the cancel tests move the robot and the plate).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from typing import Any
from uuid import uuid4

import pytest
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState
from sila2.client import SilaClient
from sila2.framework import DefinedExecutionError, InvalidMetadata, UndefinedExecutionError

from labware_model.holders import GRIPPER, HotelSlot, Nest
from ros_bridge.topics import TopicMirror
from sila_labware.servers.robot_server.cancellable_commands import CancellableCommands
from tests.helpers.sila_stack import client_for, start_stack
from tests.helpers.sim_parameters import set_node_parameter
from tests.helpers.transfer_steps import Cell, finish, wait_for_progress
from tiago_ros_hardware.topics import stamp_seconds

PLATE = "plate_001"
A1, B1 = ("station_a", 1), ("station_b", 1)
CORE = "org.silastandard/core"
CANCEL_CONTROLLER = "org.silastandard/core.commands/CancelController/v1"


@pytest.fixture(scope="module")
def cell(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cell]:
    deployment = start_stack(tmp_path_factory.mktemp("core_features"), insecure=True)
    yield Cell(deployment)
    deployment.stop()


def all_clients(cell: Cell) -> dict[str, SilaClient]:
    return {"robot": cell.robot, **cell.stations}


def sila_error(call: Callable[[], Any]) -> Exception:
    """The SiLA error a call raises (it must raise one)."""
    try:
        call()
    except (DefinedExecutionError, UndefinedExecutionError, InvalidMetadata) as error:
        return error
    raise AssertionError("the call succeeded")


def defined_error(identifier: str, call: Callable[[], Any], match: str = "") -> DefinedExecutionError:
    error = sila_error(call)
    assert isinstance(error, DefinedExecutionError), repr(error)
    assert error.identifier == identifier, repr(error)
    assert match in error.message, error.message
    return error


@pytest.fixture
def realtime(cell: Cell) -> Iterator[None]:
    """Motions paced at real time: they take seconds of wall time, so a cancel lands mid-motion."""
    set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 1.0)
    try:
        yield
    finally:
        set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 0.0)


def end_of(instance: Any, timeout_s: float = 30.0) -> Exception:
    """Wait for a command that must fail, return its SiLA error."""
    return sila_error(lambda: finish(instance, timeout_s))


def cancel(cell: Cell, instance: Any) -> None:
    cell.robot.CancelController.CancelCommand(CommandExecutionUUID=str(instance.execution_uuid))


def wait_idle(cell: Cell, timeout_s: float = 3.0) -> None:
    """The robot's state topic may lag the command's end by a few messages."""
    deadline = time.monotonic() + timeout_s
    while cell.robot_state() != "Idle" and time.monotonic() < deadline:
        time.sleep(0.05)
    assert cell.robot_state() == "Idle"


def base_pose(cell: Cell) -> tuple[float, float, float]:
    pose = cell.robot.MobileRobotController.RobotPose.get()
    return pose.X, pose.Y, pose.Theta


def assert_base_at_rest(cell: Cell) -> None:
    """The reported pose holds still: within 1 cm and 0.01 rad over a second (many seconds simulated).
    A base still rolling moves by centimetres; a standing one's localised pose may settle by a few
    millimetres with the scans matched just after it stopped (README, "Base laser and localisation")."""
    before = base_pose(cell)
    time.sleep(1.0)  # unpaced again: a second of wall time is many seconds of simulated time
    after = base_pose(cell)
    assert max(abs(a - b) for a, b in zip(before, after, strict=True)) < 0.01, (before, after)


def assert_joints_at_rest(cell: Cell) -> None:
    """No joint moves more than 1 mrad over a second of wall time (many seconds simulated), counted
    from half a second of robot time after the report: a held joint settles by a few mrad when the
    physics step changes as the last motion ends (the step's length sets a position motor's
    stiffness: docs/explanation/simulation-model.md)."""
    runtime = cell.deployment.runtime
    assert runtime is not None
    joints = TopicMirror(runtime, JointState, "/joint_states", QoSProfile(depth=5))

    try:
        settled_from = stamp_seconds(joints.wait_for_message(10.0)) + 0.5
        before = joints.wait_for_message(10.0, lambda m: stamp_seconds(m) >= settled_from)
        time.sleep(1.0)
        after = joints.wait_for_message(10.0, lambda m: m.header.stamp != before.header.stamp)
    finally:
        joints.destroy()
    assert list(before.name) == list(after.name)
    moved = {
        name: round(b - a, 4)
        for name, a, b in zip(before.name, before.position, after.position, strict=True)
        if abs(b - a) > 1e-3
    }
    assert moved == {}, f"joints still moving after the cancel: {moved}"


# --------------------------------------------------------------------------------------------------
# What each server serves; SimulationController
# --------------------------------------------------------------------------------------------------


def test_every_server_lists_the_core_features(cell: Cell) -> None:
    for role, client in all_clients(cell).items():
        served = set(client.SiLAService.ImplementedFeatures.get())
        expected = {
            f"{CORE}/SiLAService/v1",
            f"{CORE}/LockController/v1",
            f"{CORE}/SimulationController/v1",
        }
        if role == "robot":
            expected.add(CANCEL_CONTROLLER)
        else:
            assert CANCEL_CONTROLLER not in served, role
        assert expected <= served, (role, served)


def test_every_server_is_simulated_and_refuses_real_mode(cell: Cell) -> None:
    for role, client in all_clients(cell).items():
        simulation = client.SimulationController
        assert simulation.SimulationMode.get() is True, role
        simulation.StartSimulationMode()
        error = defined_error("StartRealModeFailed", lambda s=simulation: s.StartRealMode(), "PyBullet")
        assert "real" in error.message, error.message
        assert simulation.SimulationMode.get() is True, role


# --------------------------------------------------------------------------------------------------
# LockController: two clients
# --------------------------------------------------------------------------------------------------


def second_client(cell: Cell, role: str) -> SilaClient:
    served = cell.deployment.robot_server() if role == "robot" else cell.deployment.station_server(role)
    return client_for(cell.deployment, served)


def probes(client: SilaClient, role: str) -> tuple[Callable[..., Any], Callable[..., Any]]:
    """(a property read, a command) of the server's protected features, each taking `metadata`.

    The command leaves the world as it is: Dock while docked ends at once; LabwareRemoved on an
    unprepared nest is refused by the protocol (InvalidCommandSequence), which shows that it got past
    the lock. Observable commands: the initiation itself is what the lock must refuse.
    """
    if role == "robot":
        return (
            lambda **kw: client.LabwareTransferManipulatorController.NumberOfInternalPositions.get(**kw),
            lambda **kw: client.MobileRobotController.Dock(**kw),
        )
    site = client.LabwareTransferSiteController
    return (
        lambda **kw: site.NumberOfInternalPositions.get(**kw),
        lambda **kw: site.LabwareRemoved(HandoverPosition=(role, 2), **kw),
    )


def token_of(client: SilaClient, token: str) -> list[Any]:
    return [client.LockController.LockIdentifier(token)]


def assert_refused(client: SilaClient, role: str, wrong_token: str) -> None:
    read, command = probes(client, role)
    for call in (read, command):
        assert isinstance(sila_error(call), InvalidMetadata)  # no token while locked
        defined_error("InvalidLockIdentifier", lambda c=call: c(metadata=token_of(client, wrong_token)))


def assert_served(client: SilaClient, role: str, metadata: list[Any] | None = None) -> None:
    read, command = probes(client, role)
    assert read(metadata=metadata) >= 1
    instance = command(metadata=metadata)  # the initiation is accepted
    if role == "robot":
        finish(instance, 30.0)
    else:
        defined_error("InvalidCommandSequence", lambda: finish(instance, 30.0))


@pytest.mark.parametrize("role", ["robot", "station_a"])
def test_a_lock_refuses_other_clients_until_its_holder_unlocks(cell: Cell, role: str) -> None:
    a, b = second_client(cell, role), second_client(cell, role)
    token = str(uuid4())
    assert_served(b, role)  # unlocked: no token needed, and one sent anyway is ignored
    assert_served(b, role, token_of(b, "not-a-lock"))
    a.LockController.LockServer(LockIdentifier=token, Timeout=60)
    try:
        assert b.LockController.IsLocked.get() is True
        assert b.SiLAService.ServerName.get()  # SiLAService and LockController stay open
        assert_refused(b, role, wrong_token="guessed")
        lock_too = b.LockController.LockServer
        defined_error("ServerAlreadyLocked", lambda: lock_too(LockIdentifier="b", Timeout=5))
        defined_error("InvalidLockIdentifier", lambda: b.LockController.UnlockServer(LockIdentifier="b"))
        assert_served(a, role, token_of(a, token))
    finally:
        a.LockController.UnlockServer(LockIdentifier=token)
    assert b.LockController.IsLocked.get() is False
    defined_error("ServerNotLocked", lambda: a.LockController.UnlockServer(LockIdentifier=token))
    assert_served(b, role)


def test_an_observable_command_with_a_wrong_token_is_refused_before_it_runs(cell: Cell) -> None:
    """No execution is created: the initiating call itself fails, so nothing moves either."""
    a, b = second_client(cell, "robot"), second_client(cell, "robot")
    servicer = cell.deployment.robot_server().server.feature_servicers["MobileRobotController"]
    pose = base_pose(cell)
    a.LockController.LockServer(LockIdentifier="holder", Timeout=60)
    try:
        with pytest.raises(DefinedExecutionError) as refused:
            b.MobileRobotController.Undock(metadata=token_of(b, "intruder"))
        assert refused.value.identifier == "InvalidLockIdentifier"
        assert dict(servicer.observable_command_managers["Undock"]) == {}  # sila2 created no execution
    finally:
        a.LockController.UnlockServer(LockIdentifier="holder")
    # nothing moved: the localised pose of a standing base may differ in its last digits when a scan
    # was matched in between (seen: 1e-10 m), a moved one by centimetres
    assert base_pose(cell) == pytest.approx(pose, abs=1e-3)
    assert cell.robot_state() == "Docked"


def test_the_lock_lapses_after_its_timeout_without_calls_and_calls_extend_it(cell: Cell) -> None:
    role = "station_b"
    a, b = second_client(cell, role), second_client(cell, role)
    read, _command = probes(a, role)
    a.LockController.LockServer(LockIdentifier="brief", Timeout=2)
    using_until = time.monotonic() + 3.0
    while time.monotonic() < using_until:  # its holder keeps using it: it holds beyond 2 s
        assert read(metadata=token_of(a, "brief")) >= 1
        time.sleep(0.5)
    assert b.LockController.IsLocked.get() is True
    assert_refused(b, role, wrong_token="other")
    time.sleep(2.5)  # no call with the token for longer than the timeout
    assert b.LockController.IsLocked.get() is False
    assert_served(b, role)
    defined_error("ServerNotLocked", lambda: a.LockController.UnlockServer(LockIdentifier="brief"))
    # Timeout 0 is "no timeout"; the robot server is locked likewise, independently of the stations.
    a.LockController.LockServer(LockIdentifier="forever", Timeout=0)
    time.sleep(1.0)
    assert b.LockController.IsLocked.get() is True
    assert cell.robot.LockController.IsLocked.get() is False
    a.LockController.UnlockServer(LockIdentifier="forever")


# --------------------------------------------------------------------------------------------------
# CancelController
# --------------------------------------------------------------------------------------------------


def test_an_unknown_execution_uuid_is_invalid_and_cancel_all_without_commands_does_nothing(
    cell: Cell,
) -> None:
    unknown = str(uuid4())
    defined_error(
        "InvalidCommandExecutionUUID",
        lambda: cell.robot.CancelController.CancelCommand(CommandExecutionUUID=unknown),
        unknown,
    )
    state, pose = cell.robot_state(), base_pose(cell)
    cell.robot.CancelController.CancelAll()
    assert (cell.robot_state(), base_pose(cell)) == (state, pose)


def test_cancel_command_ends_a_running_drive_and_the_robot_stays_where_it_stopped(
    cell: Cell, realtime: None
) -> None:
    motion = cell.robot.MobileRobotController
    finish(motion.Undock())
    drive = motion.DriveToPointOfInterest(PointOfInterest="lab_centre")
    wait_for_progress(drive, 0.05)
    cancel(cell, drive)
    error = end_of(drive)
    assert isinstance(error, DefinedExecutionError) and error.identifier == "MotionStopped", repr(error)
    assert "cancelled by a client (CancelController.CancelCommand)" in error.message, error.message
    set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 0.0)
    wait_idle(cell)  # the state topic's last report of the motion (it lags the command's end)
    assert_base_at_rest(cell)
    assert motion.CurrentPointOfInterest.get() != "lab_centre"
    # Its execution has ended: cancelling it again names the UUID as not running.
    defined_error("InvalidCommandExecutionUUID", lambda: cancel(cell, drive), str(drive.execution_uuid))


def test_a_command_this_server_cannot_cancel_is_operation_not_supported_and_cancel_all_ends_a_drive(
    cell: Cell, realtime: None
) -> None:
    """Every observable command of the robot server can be cancelled today; the refusal is checked with
    the server's real executions and a table that lists none as cancellable."""
    served = cell.deployment.robot_server().server
    drive = cell.robot.MobileRobotController.DriveToPointOfInterest(PointOfInterest="lab_centre")
    wait_for_progress(drive, 0.05)
    nothing_cancellable = CancellableCommands(served, served.robot, cancellable_commands=())
    with pytest.raises(DefinedExecutionError) as refused:
        nothing_cancellable.cancel(drive.execution_uuid, "test")
    assert refused.value.identifier == "OperationNotSupported"
    assert "DriveToPointOfInterest" in refused.value.message
    assert not drive.done
    cell.robot.CancelController.CancelAll()
    error = end_of(drive)
    assert isinstance(error, DefinedExecutionError) and error.identifier == "MotionStopped", repr(error)
    assert "CancelController.CancelAll" in error.message, error.message
    wait_idle(cell)


def test_cancel_command_ends_a_running_prepare_and_the_protocol_starts_over(
    cell: Cell, realtime: None
) -> None:
    manipulator = cell.manipulator
    prepare = manipulator.PrepareForInput(
        HandoverPosition=A1, InternalPosition=1, LabwareType="", LabwareUniqueID=PLATE
    )
    wait_for_progress(prepare, 0.05)
    cancel(cell, prepare)
    error = end_of(prepare)
    # The standard's one error of PrepareForInput: the drive did not arrive, nothing is prepared.
    assert isinstance(error, DefinedExecutionError), repr(error)
    assert error.identifier == "InvalidCommandSequence" and "nothing is prepared" in error.message
    assert "cancelled by a client (CancelController.CancelCommand)" in error.message, error.message
    set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 0.0)
    wait_idle(cell)  # the state topic's last report of the motion (it lags the command's end)
    assert_base_at_rest(cell)
    defined_error(
        "InvalidCommandSequence",
        lambda: finish(manipulator.GetLabware(HandoverPosition=A1, IntermediateActions=[])),
        "needs PrepareForInput first",
    )


def test_cancel_command_ends_a_running_get_labware_and_the_inventory_stays_true(cell: Cell) -> None:
    cell.prepare_pick(A1, PLATE)
    set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 1.0)
    get = cell.manipulator.GetLabware(HandoverPosition=A1, IntermediateActions=[])
    try:
        wait_for_progress(get, 0.03)  # early in the reach for the plate: the cancel lands before the grasp
        cancel(cell, get)
        error = end_of(get)
    finally:
        set_node_parameter(cell.deployment.runtime, "realtime_factor_cap", 0.0)
        if not get.done:  # never leave the command running
            cell.robot.CancelController.CancelAll()
    assert isinstance(error, DefinedExecutionError) and error.identifier == "LabwareNotPicked", repr(error)
    assert "CANCELED" in error.message and "CancelController.CancelCommand" in error.message, error.message
    wait_idle(cell)
    assert_joints_at_rest(cell)

    where = cell.physical_location(PLATE)
    assert where in {Nest("station_a", 1), HotelSlot(1), GRIPPER}, where
    assert cell.reported_location(PLATE) == where
    assert cell.nest_occupied()[A1] == (where == Nest("station_a", 1))

    # The robot takes new commands: a complete transfer follows. Station A is still prepared for
    # output, so the scheduler redoes the robot's part, then closes A and places in B.
    assert where == Nest("station_a", 1), f"cancel landed after the grasp: plate at {where}"
    cell.prepare_pick(A1, PLATE, station_too=False)
    cell.pick(A1)
    cell.place(B1, PLATE)
    assert cell.physical_location(PLATE) == cell.reported_location(PLATE) == Nest("station_b", 1)
    assert cell.deployment.link is not None
    assert cell.deployment.link.check_placement(PLATE, Nest(*B1)).in_nest
