"""Each script in examples/ runs against a real stack (sim node, sequencer, bridge, SiLA servers
with TLS), as a person would run it against `serve`; physics ground truth then says where the
plates are.

The world is the default lab with a second plate in station_a/2. The tests share the stack and
run in file order, handing the plates on: the batch moves both plates to station_b, the single
transfer brings plate_001 back to station_a/1 and docks, the Bluesky exchange takes it to the beam
nest station_b/1 and back.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest

from labware_model.holders import Nest
from sila_labware.client.sequence import PICK_STEPS, PLACE_STEPS, TRANSFER_STEPS
from sila_labware.deployment.stack import Deployment
from tests.helpers.sila_stack import REPOSITORY, start_stack
from tests.helpers.world_variants import default_world_with

EXAMPLES = REPOSITORY / "examples"
FIRST, SECOND = "plate_001", "plate_002"


def load_example(name: str) -> ModuleType:
    """An example script as a module (they are scripts, not a package)."""
    spec = importlib.util.spec_from_file_location(f"example_{name}", EXAMPLES / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def world_with_two_plates(directory: Path) -> Path:
    """The default world with a second plate in station_a/2; station_b's two nests are free."""
    return default_world_with(directory / "two_plates.yaml", {SECOND: ("station_a", 2)})


@pytest.fixture(scope="module")
def stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Deployment]:
    directory = tmp_path_factory.mktemp("examples")
    deployment = start_stack(directory, world=world_with_two_plates(directory))
    yield deployment
    deployment.stop()


def connection_arguments(stack: Deployment) -> list[str]:
    """What a person copies from `serve`'s output: the robot's and the stations' addresses, the CA."""
    robot = stack.robot_server()
    arguments = ["--robot", f"{robot.host}:{robot.port}", "--ca-file", str(stack.ca_file)]
    for served in stack.servers:
        if served.role == "station":
            arguments += ["--station", f"{served.host}:{served.port}"]
    return arguments


def assert_in_nest(stack: Deployment, plate: str, station: str, sub_position: int) -> None:
    assert stack.link is not None
    placement = stack.link.check_placement(plate, Nest(station, sub_position))
    assert placement.in_nest, f"{plate} is not in {station}/{sub_position}: it is at {placement.location}"


def finished_steps(output: str) -> list[str]:
    return [line.split("  ")[0] for line in output.splitlines() if " done in " in line]


def test_batch_picks_two_plates_into_both_internal_positions_then_places_both(
    stack: Deployment, capsys: pytest.CaptureFixture[str]
) -> None:
    moves = ["--move", "station_a/1", "station_b/1", FIRST, "--move", "station_a/2", "station_b/2", SECOND]
    assert load_example("batch_two_plates").main([*connection_arguments(stack), *moves]) == 0
    output = capsys.readouterr().out
    assert finished_steps(output) == list(PICK_STEPS * 2 + PLACE_STEPS * 2), output
    assert f"on board: {FIRST} in internal position 1" in output, output
    assert f"on board: {SECOND} in internal position 2" in output
    assert_in_nest(stack, FIRST, "station_b", 1)
    assert_in_nest(stack, SECOND, "station_b", 2)


def test_one_transfer_moves_the_plate_and_docks(
    stack: Deployment, capsys: pytest.CaptureFixture[str]
) -> None:
    route = ["--source", "station_b/1", "--destination", "station_a/1", "--plate", FIRST]
    assert load_example("one_transfer").main([*connection_arguments(stack), *route]) == 0
    output = capsys.readouterr().out
    assert finished_steps(output) == [*TRANSFER_STEPS, "Robot.Dock"], output
    assert f"the robot's inventory has {FIRST} at station_a/1" in output
    assert_in_nest(stack, FIRST, "station_a", 1)
    assert stack.link is not None and stack.link.robot_status().docked


def test_one_transfer_names_a_refusal_and_exits_non_zero(
    stack: Deployment, capsys: pytest.CaptureFixture[str]
) -> None:
    """A station no server serves is refused by the client itself, before anything moves."""
    route = ["--source", "station_a/1", "--destination", "station_z/1", "--plate", FIRST]
    assert load_example("one_transfer").main([*connection_arguments(stack), *route]) == 1
    error = capsys.readouterr().err
    assert "failed: ParameterRejected: transfer: no connected station serves 'station_z'" in error, error
    assert_in_nest(stack, FIRST, "station_a", 1)


def test_bluesky_exchange_measures_the_plate_and_brings_it_back(
    stack: Deployment, capsys: pytest.CaptureFixture[str]
) -> None:
    arguments = ["--domain-id", str(stack.domain_id), "--storage", "station_a/1", "--beam", "station_b/1"]
    assert load_example("bluesky_exchange").main([*arguments, "--plate", FIRST]) == 0
    output = capsys.readouterr().out
    assert "measured: detector" in output and "run success" in output, output
    assert_in_nest(stack, FIRST, "station_a", 1)
