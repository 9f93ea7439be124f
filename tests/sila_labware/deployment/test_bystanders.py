"""A transfer that delivers its plate but moves another out of its nest is no delivery: the demo asks
physics about every other plate of the world file, before and after (`bystanders`)."""

from __future__ import annotations

import io
from pathlib import Path

from labware_model.holders import HotelSlot, Nest
from sila_labware.benchmarks.failure_causes import classify_failure
from sila_labware.deployment.demo import DISTURBED, run_demo
from sila_labware.deployment.plate_names import plate_named_at, plates_at_start
from tests.helpers.sila_stack import DEFAULT_WORLD, start_stack
from tests.helpers.sim_parameters import set_node_parameter

THREE_STATIONS = DEFAULT_WORLD.parent / "three_stations.yaml"
BYSTANDER = "mp_001"  # in reader/1, beside the nest the demo's deep-well plate goes into


class _AfterTheGet(io.StringIO):
    """The demo's progress stream: once GetLabware is done, `act` runs (the robot is on its way)."""

    def __init__(self, act) -> None:  # noqa: ANN001 - a callable
        super().__init__()
        self.act, self.done = act, False

    def write(self, text: str) -> int:
        if not self.done and "Robot.GetLabware" in text and "done" in text:
            self.done = True
            self.act()
        return super().write(text)


def test_the_world_files_plates_are_read_with_where_they_start(tmp_path: Path) -> None:
    world = tmp_path / "lab.yaml"
    world.write_text(
        "plates:\n"
        "  - {id: p1, type: t, station: reader, sub_position: 2}\n"
        "  - {id: p2, type: t, hotel_slot: 1}\n"
        "  - {type: t, station: reader, sub_position: 3}\n"  # no id: not a plate the demo can name
    )
    assert plates_at_start(world) == {"p1": Nest("reader", 2), "p2": HotelSlot(1)}
    assert plate_named_at(world, Nest("reader", 2)) == "p1"
    assert plate_named_at(world, Nest("reader", 3)) == ""
    assert plates_at_start(tmp_path / "missing.yaml") == {}


def test_a_plate_taken_from_its_nest_during_the_transfer_fails_the_delivery_as_a_collision(
    tmp_path: Path,
) -> None:
    """The deep-well plate arrives in reader/2, but the microplate beside it in reader/1 was taken
    away while the robot drove (the sim's fault injection puts it on the floor): not delivered."""
    deployment = start_stack(tmp_path, insecure=True, world=THREE_STATIONS)
    try:
        assert deployment.runtime is not None
        runtime = deployment.runtime
        stream = _AfterTheGet(lambda: set_node_parameter(runtime, "fault.remove_plate", BYSTANDER))
        report = run_demo(deployment, progress_stream=stream)
    finally:
        deployment.stop()
    assert stream.done, stream.getvalue()
    assert (report.labware_id, report.destination) == ("dw_001", "reader/2")
    assert report.plate_position_error_mm is not None and report.plate_position_error_mm < 5.0
    assert not report.success
    assert report.error.startswith(DISTURBED), report.error
    assert f"{BYSTANDER} is no longer in reader/1: it is at " in report.error
    assert classify_failure(report) == "collision"
