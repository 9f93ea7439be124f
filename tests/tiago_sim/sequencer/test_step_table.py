"""The estimates table from sequencer logs: medians per step kind, in plan order, as parameter names."""

from __future__ import annotations

from pathlib import Path

from tiago_sim.sequencer.step_durations import table_from_parameters
from tiago_sim.sequencer.step_table import durations_by_kind, main, table_rows

LOG_A = """\
[INFO] [labware_sequencer]: GetLabware:marker_motion:work_pose:final_approach took 2.70 s (estimated 3.10 s)
[INFO] [labware_sequencer]: step 2 of 12: gripper open
[INFO] [labware_sequencer]: GetLabware:gripper:open:opening took 0.60 s (estimated 0.30 s)
[INFO] [labware_sequencer]: GetLabware:navigate:station_b_work:driving took 7.00 s (estimated 8.50 s)
"""
LOG_B = """\
[INFO] [labware_sequencer]: GetLabware:marker_motion:work_pose:final_approach took 3.10 s (estimated 2.70 s)
"""
LOG_C = """\
[INFO] [labware_sequencer]: GetLabware:marker_motion:work_pose:final_approach took 6.00 s (estimated 2.90 s)
"""


def test_each_task_kind_gets_its_median_and_drives_are_left_to_the_action_row(tmp_path: Path, capsys) -> None:
    for name, log in (("a", LOG_A), ("b", LOG_B), ("c", LOG_C)):
        (tmp_path / f"{name}.log").write_text(log)
    assert main([str(tmp_path / f"{name}.log") for name in "abc"]) == 0
    rows = capsys.readouterr().out.splitlines()
    # the median of 2.70, 3.10 and 6.00 (their mean, 3.93, is the one hard lab's)
    assert rows[0].startswith("  GetLabware.marker_motion.work_pose.final_approach: 3.10  # n=3, 2.70..6.00")
    assert rows[1].startswith("  GetLabware.gripper.open.opening: 0.60  # n=1")
    assert len(rows) == 2, "a drive's duration belongs to its lab: no row"


def test_the_rows_read_back_as_the_sequencers_table() -> None:
    rows = table_rows(durations_by_kind(LOG_A.splitlines()))
    parameters = {row.split(":")[0].strip(): float(row.split(":")[1].split("#")[0]) for row in rows}
    table = table_from_parameters(parameters)
    assert table == {
        "GetLabware:marker_motion:work_pose:final_approach": 2.7,
        "GetLabware:gripper:open:opening": 0.6,
    }


def test_no_logs_is_a_usage_error() -> None:
    assert main([]) == 2
