"""Each example world besides the default delivers one plate end to end: the whole stack (sim node,
sequencer, bridge, SiLA servers) started on it and the demo's transfer (the first station's plate
to the second station's first free nest), judged by physics ground truth.

Why: an example world is a promise that the robot serves that layout; the robot is tuned to
layouts like the default, and a layout that loads is not yet one it reaches (README, "Schema")."""

from __future__ import annotations

from pathlib import Path

import pytest

from labware_model.holders import Nest
from sila_labware.deployment.clients import transfer_client
from sila_labware.deployment.demo import run_demo
from tests.helpers.sila_stack import DEFAULT_WORLD, start_stack

LONG_ROW = DEFAULT_WORLD.parent / "long_row.yaml"
UNUSUAL = DEFAULT_WORLD.parent / "unusual_benches.yaml"
CARRIED_AROUND = (LONG_ROW, UNUSUAL)  # their tests carry a plate further than the demo does
EXAMPLES = sorted(
    path for path in DEFAULT_WORLD.parent.glob("*.yaml") if path not in (DEFAULT_WORLD, *CARRIED_AROUND)
)
# what the demo moves in each: the plate, from, to
EXPECTED = {
    "bench_in_the_way": ("plate_001", "station_a/1", "station_b/1"),  # around bench_c, untouched
    "furnished_lab": ("plate_001", "station_a/1", "station_b/1"),  # around a pillar and a cart
    "two_benches": ("plate_b", "bench_a/2", "bench_b/1"),
    "three_stations": ("dw_001", "sealer/1", "reader/2"),  # the deep-well plate
    "standing_benches": ("plate_001", "station_a/1", "station_b/1"),  # 0.90 m, no robot fields
}
# long_row.yaml: reader/1 into the middle nest between two full ones, then to each end of the row
ALONG_THE_ROW = (("reader", 1), ("plate_store", 3), ("plate_store", 6), ("plate_store", 1))
# low_bench (0.60 m, heading 0) -> high_bench (0.78 m, 90) -> back_bench (180) -> corner_bench (-135)
# -> side_marker_bench (-90, its marker far right of the working pose); the first leg is its demo
AROUND = (
    ("low_bench", 1),
    ("high_bench", 1),
    ("back_bench", 2),
    ("corner_bench", 1),
    ("side_marker_bench", 1),
)


def test_every_example_world_has_a_transfer_here() -> None:
    assert sorted(path.stem for path in EXAMPLES) == sorted(EXPECTED)
    assert all(world.exists() for world in CARRIED_AROUND)


@pytest.mark.parametrize("world", EXAMPLES, ids=[path.stem for path in EXAMPLES])
def test_an_example_world_delivers_the_demo_plate(tmp_path: Path, world: Path) -> None:
    deployment = start_stack(tmp_path, insecure=True, world=world)
    try:
        report = run_demo(deployment, progress_stream=None)
    finally:
        deployment.stop()
    assert (report.labware_id, report.source, report.destination) == EXPECTED[world.stem]
    assert report.success, f"ground truth says the plate is not in its nest: {report}"
    assert report.plate_position_error_mm is not None and report.plate_position_error_mm < 5.0


def _carry(tmp_path: Path, world: Path, legs: tuple[tuple[str, int], ...], plate: str) -> None:
    """One plate along `legs` in `world`, each leg judged by physics: it rests in its nest within 5 mm."""
    deployment = start_stack(tmp_path, insecure=True, world=world)
    try:
        assert deployment.link is not None
        with transfer_client(deployment) as client:
            for source, destination in zip(legs, legs[1:], strict=False):
                client.transfer(source, destination, labware_id=plate)
                placement = deployment.link.check_placement(plate, Nest(*destination), timeout_s=10.0)
                assert placement.in_nest, f"{source} -> {destination}: {placement}"
                assert 1000.0 * placement.position_error_m < 5.0
    finally:
        deployment.stop()


def test_a_row_of_six_nests_on_a_standing_bench_takes_a_plate_into_its_middle_and_both_ends(
    tmp_path: Path,
) -> None:
    """Six nests 0.15 m apart on a 0.90 m bench, no robot field in the file: the plate goes between
    two full neighbours (nests 2 and 4), then into the far end (beside nest 5) and the near end (beside
    nest 2), which lie beyond the arm's band from the station's working pose."""
    _carry(tmp_path, LONG_ROW, ALONG_THE_ROW, "plate_001")


def test_one_plate_goes_round_benches_of_every_height_and_heading(tmp_path: Path) -> None:
    """The unusual layouts of the random-layout issue in one lab: the lowest and highest bench top the
    robot serves, bench headings 0, 90, 180, -135 and -90 degrees and a marker far right of the
    working pose; each leg is judged by physics."""
    _carry(tmp_path, UNUSUAL, AROUND, "plate_001")
