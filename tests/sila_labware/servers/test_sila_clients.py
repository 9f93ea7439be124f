"""The standard transfer through an independent SiLA client: `unitelabs-sila` (async, its own
gRPC and protobuf code) drives a deployment served by the `sila2` library.

TLS is on, with the deployment's CA as root certificate; the robot server is found by zeroconf
discovery (by server UUID, so parallel runs on this machine cannot be mistaken for ours). The
plate must end physically in station_b's nest: judged from the simulation's ground truth.
"""

from __future__ import annotations

import asyncio
import uuid
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import pytest
from sila.client import Client, ClientConfig
from sila.framework import CommandExecutionInfo, DefinedExecutionError

from labware_model.holders import Nest
from sila_labware.deployment.stack import Deployment, ServedServer
from tests.helpers.sila_stack import start_stack
from tests.helpers.transfer_steps import finish

PLATE = "plate_001"
SOURCE, DESTINATION = ("station_a", 1), ("station_b", 1)
COMMAND_TIMEOUT_S = 300.0


@dataclass
class ExecutionTrace:
    """What a client saw of one observable command: status values with progress and remaining time."""

    name: str
    progress: list[float] = field(default_factory=list)
    remaining_s: list[float] = field(default_factory=list)
    final_status: str = ""


# Discovery by name finds every lab announced on this machine: a name of this run's own, so that a
# `demo` or another test run beside it (the default lab's name) is never taken for ours.
LAB = f"lab {uuid.uuid4().hex[:8]}"


@pytest.fixture(scope="module")
def stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Deployment]:
    deployment = start_stack(tmp_path_factory.mktemp("unitelabs"), discovery=True, lab_name=LAB)
    yield deployment
    deployment.stop()


def handover(position: tuple[str, int]) -> dict[str, Any]:
    return {"Position": position[0], "SubPosition": position[1]}


async def run_observable(name: str, command: Any, **parameters: Any) -> ExecutionTrace:
    """Execute, follow the status stream to its end, then fetch the responses (raises SiLA errors)."""
    trace = ExecutionTrace(name)
    execution = await command(**parameters)
    status: CommandExecutionInfo
    async for status in await execution.subscribe_status():
        if status.progress is not None:
            trace.progress.append(status.progress.value)
        if status.remaining_time is not None:
            trace.remaining_s.append(status.remaining_time.total_seconds)
        trace.final_status = status.status.name
    await execution.get_responses()
    return trace


async def together(*runs: Any) -> list[ExecutionTrace]:
    return list(await asyncio.wait_for(asyncio.gather(*runs), COMMAND_TIMEOUT_S))


async def open_client(served: ServedServer, root_certificates: bytes) -> Client:
    client = Client(
        ClientConfig(
            served.host, served.port, tls=True, root_certificates=root_certificates, default_timeout=30_000
        )
    )
    await client.open()
    return client


async def standard_transfer(stack: Deployment) -> list[ExecutionTrace]:
    """The six steps of the standard, as a scheduler written against unitelabs-sila sends them."""
    assert stack.ca_file is not None
    root_certificates = stack.ca_file.read_bytes()
    robot_uuid = stack.robot_server().server.server_uuid
    robot = await Client.discover(uuid=str(robot_uuid), timeout=20_000, root_certificates=root_certificates)
    await robot.open(timeout=30_000)
    source = await open_client(stack.station_server(SOURCE[0]), root_certificates)
    destination = await open_client(stack.station_server(DESTINATION[0]), root_certificates)
    try:
        assert await robot.get_server_uuid() == str(robot_uuid)
        manipulator = robot.LabwareTransferManipulatorController
        positions = await manipulator.AvailableHandoverPositions.read()
        # Here SubPosition is the number of sub-positions of each station.
        assert {item.Position: item.SubPosition for item in positions}[SOURCE[0]] >= SOURCE[1]
        assert {item.Position for item in positions} >= {SOURCE[0], DESTINATION[0]}
        assert await manipulator.NumberOfInternalPositions.read() >= 1

        traces = await together(
            run_observable(
                "A.PrepareForOutput",
                source.LabwareTransferSiteController.PrepareForOutput,
                HandoverPosition=handover(SOURCE),
                InternalPosition=1,
            ),
            run_observable(
                "Robot.PrepareForInput",
                manipulator.PrepareForInput,
                HandoverPosition=handover(SOURCE),
                InternalPosition=1,
                LabwareType="",
                LabwareUniqueID=PLATE,
            ),
        )
        traces += await together(
            run_observable(
                "Robot.GetLabware",
                manipulator.GetLabware,
                HandoverPosition=handover(SOURCE),
                IntermediateActions=[],
            )
        )
        traces += await together(
            run_observable(
                "A.LabwareRemoved",
                source.LabwareTransferSiteController.LabwareRemoved,
                HandoverPosition=handover(SOURCE),
            )
        )
        traces += await together(
            run_observable(
                "B.PrepareForInput",
                destination.LabwareTransferSiteController.PrepareForInput,
                HandoverPosition=handover(DESTINATION),
                InternalPosition=1,
                LabwareType="",
                LabwareUniqueID=PLATE,
            ),
            run_observable(
                "Robot.PrepareForOutput",
                manipulator.PrepareForOutput,
                HandoverPosition=handover(DESTINATION),
                InternalPosition=1,
            ),
        )
        traces += await together(
            run_observable(
                "Robot.PutLabware",
                manipulator.PutLabware,
                HandoverPosition=handover(DESTINATION),
                IntermediateActions=[],
            )
        )
        traces += await together(
            run_observable(
                "B.LabwareDelivered",
                destination.LabwareTransferSiteController.LabwareDelivered,
                HandoverPosition=handover(DESTINATION),
            )
        )
        location = (await robot.LabwareInventory.LocateLabware(LabwareUniqueID=PLATE)).Location
        assert (location.Aboard, location.Position, location.Index) == (False, *DESTINATION)

        # Out of order: the protocol is over, so GetLabware must be refused with the standard's error.
        with pytest.raises(DefinedExecutionError, match="needs PrepareForInput first") as refused:
            await run_observable(
                "Robot.GetLabware again",
                manipulator.GetLabware,
                HandoverPosition=handover(DESTINATION),
                IntermediateActions=[],
            )
        assert refused.value.identifier == "InvalidCommandSequence"
        return traces
    finally:
        for client in (robot, source, destination):
            await client.close()


def test_unitelabs_client_moves_the_plate_from_a_to_b(stack: Deployment) -> None:
    traces = asyncio.run(standard_transfer(stack))

    assert [trace.final_status for trace in traces] == ["FINISHED_SUCCESSFULLY"] * len(traces)
    get_labware = next(trace for trace in traces if trace.name == "Robot.GetLabware")
    assert get_labware.progress and get_labware.progress[-1] == pytest.approx(1.0)
    assert get_labware.progress == sorted(get_labware.progress), "progress never goes down"
    assert len(set(get_labware.progress)) >= 3, get_labware.progress
    assert get_labware.remaining_s[-1] <= max(get_labware.remaining_s)

    # Physics ground truth: the plate rests in B's nest, A's nest is empty.
    assert stack.link is not None
    placement = stack.link.check_placement(PLATE, Nest(*DESTINATION))
    assert placement.found and placement.in_nest, placement
    assert placement.position_error_m < 0.005, placement
    nests = {reading.nest: reading.occupied for reading in stack.link.nest_readings()}
    assert nests[Nest(*DESTINATION)] and not nests[Nest(*SOURCE)]


def test_sila2_discovery_by_name_without_a_ca_file_runs_a_transfer(stack: Deployment) -> None:
    """SiLA 2 Part B: a client given no root certificate takes the CA from the discovery record and
    accepts the servers because their certificates' common name is SiLA2. Found by name alone, the
    robot and both stations move the plate back from B to A, in the standard's order."""
    from sila2.client import SilaClient

    clients = {
        role: SilaClient.discover(server_name=served.name, timeout=20)
        for role, served in (
            ("robot", stack.robot_server()),
            ("a", stack.station_server(SOURCE[0])),
            ("b", stack.station_server(DESTINATION[0])),
        )
    }
    try:
        robot = clients["robot"].LabwareTransferManipulatorController
        site_a, site_b = (clients[key].LabwareTransferSiteController for key in ("a", "b"))
        assert clients["robot"].SiLAService.ServerUUID.get() == str(stack.robot_server().server.server_uuid)
        pick, place = handover(DESTINATION), handover(SOURCE)  # the plate is in B after the test above
        for step in (
            [
                lambda: site_b.PrepareForOutput(HandoverPosition=pick, InternalPosition=1),
                lambda: robot.PrepareForInput(
                    HandoverPosition=pick, InternalPosition=1, LabwareType="", LabwareUniqueID=PLATE
                ),
            ],
            [lambda: robot.GetLabware(HandoverPosition=pick, IntermediateActions=[])],
            [lambda: site_b.LabwareRemoved(HandoverPosition=pick)],
            [
                lambda: site_a.PrepareForInput(
                    HandoverPosition=place, InternalPosition=1, LabwareType="", LabwareUniqueID=PLATE
                ),
                lambda: robot.PrepareForOutput(HandoverPosition=place, InternalPosition=1),
            ],
            [lambda: robot.PutLabware(HandoverPosition=place, IntermediateActions=[])],
            [lambda: site_a.LabwareDelivered(HandoverPosition=place)],
        ):
            for instance in [start() for start in step]:
                finish(instance)
        assert stack.link is not None
        assert stack.link.check_placement(PLATE, Nest(*SOURCE)).in_nest
    finally:
        for client in clients.values():
            client._channel.close()  # sila2 0.14 offers no public close


def test_two_labs_on_one_network_are_told_apart_by_name(
    stack: Deployment, tmp_path_factory: pytest.TempPathFactory
) -> None:
    """Two labs announce themselves at once; discovery by server name (the lab's name in it), with
    no CA file, reaches each lab's own robot."""
    from sila2.client import SilaClient

    second = start_stack(tmp_path_factory.mktemp("second_lab"), discovery=True, lab_name=f"second {LAB}")
    try:
        for lab, name in (
            (stack, f"TIAGo Labware Robot ({LAB})"),
            (second, f"TIAGo Labware Robot (second {LAB})"),
        ):
            assert lab.robot_server().name == name
            client = SilaClient.discover(server_name=name, timeout=20)
            try:
                assert client.SiLAService.ServerUUID.get() == str(lab.robot_server().server.server_uuid)
            finally:
                client._channel.close()  # sila2 0.14 offers no public close
    finally:
        second.stop()
