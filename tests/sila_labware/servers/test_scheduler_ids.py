"""A scheduler names its own plates: its LabwareUniqueIDs are names, the sensors say where.

An independent client (`unitelabs-sila`, knowing only the standard) drives the whole standard
sequence with ids the world file does not know (the plates' labels read `plate_001` and
`plate_002`): A -> B, then a batch of two through both internal positions that brings the first
plate back B -> A and the second A -> B. Every step must succeed; the robot's LabwareInventory
answers by the scheduler's names; an id that names a plate aboard is refused at PrepareForInput;
the plates' final places are judged from the physics' ground truth (by their labels).
"""

from __future__ import annotations

import asyncio
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from sila.client import Client, ClientConfig
from sila.framework import DefinedExecutionError

from labware_model.holders import Nest
from sila_labware.deployment.stack import Deployment
from tests.helpers.sila_stack import DEFAULT_WORLD, start_stack

A1, A2, B1, B2 = ("station_a", 1), ("station_a", 2), ("station_b", 1), ("station_b", 2)
FIRST, SECOND = "p1", "hidden-2"  # the scheduler's names
LABELS = {FIRST: "plate_001", SECOND: "plate_002"}  # what the plates' labels read
TIMEOUT_S = 300.0


def two_plate_world(directory: Path) -> Path:
    """The default lab with a second plate in station_a's second nest."""
    world = yaml.safe_load(DEFAULT_WORLD.read_text())
    second = dict(world["plates"][0], id=LABELS[SECOND], station="station_a", sub_position=2)
    world["plates"].append(second)
    path = directory / "two_plates.yaml"
    path.write_text(yaml.safe_dump(world, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Deployment]:
    directory = tmp_path_factory.mktemp("scheduler_ids")
    deployment = start_stack(
        directory, world=two_plate_world(directory), lab_name=f"ids {uuid.uuid4().hex[:8]}"
    )
    yield deployment
    deployment.stop()


def handover(position: tuple[str, int]) -> dict[str, Any]:
    return {"Position": position[0], "SubPosition": position[1]}


async def run(command: Any, **parameters: Any) -> str:
    """Run an observable command to its end; its final status (raises its SiLA error)."""
    execution = await command(**parameters)
    final = ""
    async for status in await execution.subscribe_status():
        final = status.status.name
    await execution.get_responses()
    return final


class Scheduler:
    """The standard's steps as a scheduler sends them, over one client per server."""

    def __init__(self, robot: Client, sites: dict[str, Client]) -> None:
        self.robot = robot.LabwareTransferManipulatorController
        self.inventory = robot.LabwareInventory
        self.sites = {name: client.LabwareTransferSiteController for name, client in sites.items()}
        self.statuses: list[str] = []

    async def together(self, *runs: Any) -> None:
        self.statuses += await asyncio.wait_for(asyncio.gather(*runs), TIMEOUT_S)

    async def get(self, source: tuple[str, int], slot: int, labware_id: str) -> None:
        site = self.sites[source[0]]
        await self.together(
            run(site.PrepareForOutput, HandoverPosition=handover(source), InternalPosition=1),
            run(
                self.robot.PrepareForInput,
                HandoverPosition=handover(source),
                InternalPosition=slot,
                LabwareType="",
                LabwareUniqueID=labware_id,
            ),
        )
        await self.together(
            run(self.robot.GetLabware, HandoverPosition=handover(source), IntermediateActions=[])
        )
        await self.together(run(site.LabwareRemoved, HandoverPosition=handover(source)))

    async def put(self, slot: int, destination: tuple[str, int], labware_id: str) -> None:
        site = self.sites[destination[0]]
        await self.together(
            run(
                site.PrepareForInput,
                HandoverPosition=handover(destination),
                InternalPosition=1,
                LabwareType="",
                LabwareUniqueID=labware_id,
            ),
            run(self.robot.PrepareForOutput, HandoverPosition=handover(destination), InternalPosition=slot),
        )
        await self.together(
            run(self.robot.PutLabware, HandoverPosition=handover(destination), IntermediateActions=[])
        )
        await self.together(run(site.LabwareDelivered, HandoverPosition=handover(destination)))

    async def refused_to_prepare(self, source: tuple[str, int], labware_id: str, says: str) -> None:
        """PrepareForInput at `source` naming `labware_id` must be refused as out of sequence."""
        with pytest.raises(DefinedExecutionError, match=says) as refused:
            await run(
                self.robot.PrepareForInput,
                HandoverPosition=handover(source),
                InternalPosition=1,
                LabwareType="",
                LabwareUniqueID=labware_id,
            )
        assert refused.value.identifier == "InvalidCommandSequence"

    async def where(self, labware_id: str) -> tuple[bool, str, int]:
        location = (await self.inventory.LocateLabware(LabwareUniqueID=labware_id)).Location
        return location.Aboard, location.Position, location.Index


async def open_client(stack: Deployment, role: str) -> Client:
    served = stack.robot_server() if role == "robot" else stack.station_server(role)
    assert stack.ca_file is not None
    client = Client(
        ClientConfig(
            served.host,
            served.port,
            tls=True,
            root_certificates=stack.ca_file.read_bytes(),
            default_timeout=30_000,
        )
    )
    await client.open()
    return client


async def scheduler_run(stack: Deployment) -> list[str]:
    clients = {role: await open_client(stack, role) for role in ("robot", "station_a", "station_b")}
    scheduler = Scheduler(clients["robot"], {name: clients[name] for name in ("station_a", "station_b")})
    try:
        await scheduler.get(A1, 1, FIRST)
        assert await scheduler.where(FIRST) == (True, "", 1)
        await scheduler.put(1, B1, FIRST)
        assert await scheduler.where(FIRST) == (False, *B1)

        # the batch: both internal positions, the first plate back to A, the second to B
        await scheduler.get(B1, 1, FIRST)
        await scheduler.get(A2, 2, SECOND)
        assert await scheduler.where(SECOND) == (True, "", 2)
        await scheduler.refused_to_prepare(A1, FIRST, "'p1' is already aboard")
        await scheduler.put(1, A1, FIRST)
        await scheduler.refused_to_prepare(B1, FIRST, "'p1' is at station_a/1, not at station_b/1")
        await scheduler.put(2, B2, SECOND)
        assert await scheduler.where(FIRST) == (False, *A1)
        assert await scheduler.where(SECOND) == (False, *B2)
        return scheduler.statuses
    finally:
        for client in clients.values():
            await client.close()


def test_a_scheduler_with_ids_of_its_own_moves_plates_a_to_b_back_and_in_a_batch(stack: Deployment) -> None:
    statuses = asyncio.run(scheduler_run(stack))
    assert statuses and set(statuses) == {"FINISHED_SUCCESSFULLY"}, statuses

    assert stack.link is not None and stack.robot is not None
    for name, nest in ((FIRST, A1), (SECOND, B2)):  # the physics, by the plates' labels
        placement = stack.link.check_placement(LABELS[name], Nest(*nest))
        assert placement.found and placement.in_nest, (name, placement)
        record = stack.robot.inventory.locate(name)
        assert record is not None and record.label == LABELS[name] and record.note, record
    assert stack.robot.inventory.locate(LABELS[FIRST]) is None, "one plate, one name"
