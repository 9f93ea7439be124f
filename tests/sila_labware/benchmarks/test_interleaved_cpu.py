"""The interleaved CPU benchmark's own parts: run order, verdict, the campaign's JSON, the CPU count.

No campaign runs here (one takes about 10 s a trial): the campaign's JSON is a real one, captured
from `sila-labware bench --trials 1 --seed 1 --jobs 1 --json` at 2818f60.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from sila_labware.benchmarks.interleaved_cpu import (
    CampaignError,
    CampaignSummary,
    checkout_problems,
    compare,
    interleaved_order,
    parse_campaign,
)

REPOSITORY = Path(__file__).resolve().parents[3]
# Captured as printed, less the per-phase timings, the disturbance levels and the trial's steps.
CAMPAIGN_STDOUT = (
    '{"seed": 1, "trials": 1, "successes": 1, "success_rate": 1.0, "failures": {"positioning": 0, '
    '"perception": 0, "grasp": 0, "navigation": 0, "collision": 0, "other": 0}, '
    '"sim_seconds_median": 64.808333333, "wall_seconds_median": 5.965101555999354, '
    '"startup_wall_seconds_median": 2.2476175369993143, "sim_seconds_total": 64.808333333, '
    '"wall_seconds_total": 5.965101555999354, "campaign_wall_seconds": 8.212719092998668, '
    '"realtime_factor": 10.864581721633812, "placement_error_mm_median": 1.2808427683589645, '
    '"placement_error_mm_max": 1.2808427683589645, "failed_trials": [], "outcomes": [{"seed": 1, '
    '"success": true, "cause": "", "error": "", "sim_seconds": 64.808333333, '
    '"wall_seconds": 5.965101555999354, "startup_wall_seconds": 2.2476175369993143, '
    '"plate_position_error_mm": 1.2808427683589645, '
    '"world": "/tmp/cpu_before/tiago_sim/worlds/default.yaml"}], "jobs": 1, "random_layouts": false, '
    '"random_obstacles": false, "elapsed_wall_seconds": 8.304196316999878, "success": true, '
    '"error": "", "error_kind": "", "exit_code": 0}\n'
)
# Captured from the same command in a checkout whose default world had moved away.
REFUSED_STDOUT = (
    '{"success": false, "error": "world file not found: /work/main/tiago_sim/worlds/default.yaml", '
    '"error_kind": "usage", "exit_code": 2}\n'
)


def test_runs_alternate_and_each_round_swaps_which_side_goes_first() -> None:
    assert interleaved_order(3) == [
        (0, "before"), (0, "after"), (1, "after"), (1, "before"), (2, "before"), (2, "after"),
    ]  # fmt: skip


def test_the_ratio_is_of_the_medians_and_the_bound_holds_both_ways() -> None:
    comparison = compare([10.0, 50.0, 11.0], [12.0, 10.5, 11.5])  # one disturbed run among three
    assert (comparison.before_median, comparison.after_median) == (11.0, 11.5)
    assert comparison.ratio == pytest.approx(11.5 / 11.0)
    assert comparison.verdict == "within 10 %"
    assert compare([10.0], [11.0]).verdict == "within 10 %"  # the bound itself is within
    assert compare([10.0], [11.2]).verdict == "over 10 %"
    assert compare([10.0], [8.5]).verdict == "over 10 %"  # 15 % cheaper did not keep the cost either


def test_a_campaigns_summary_gives_its_trials_and_deliveries() -> None:
    stdout = "a line a child printed\n" + CAMPAIGN_STDOUT
    assert parse_campaign(stdout) == CampaignSummary(trials=1, delivered=1, failed=())


def test_a_failed_trial_is_named_by_its_seed_and_cause() -> None:
    summary = json.loads(CAMPAIGN_STDOUT)
    error = "Robot.GetLabware: the plate slipped"
    summary.update(successes=0, failed_trials=[{"seed": 1, "cause": "grasp", "error": error, "world": ""}])
    parsed = parse_campaign(json.dumps(summary))
    assert (parsed.trials, parsed.delivered) == (1, 0)
    assert parsed.failed == (f"seed 1: grasp ({error})",)


def test_a_run_without_a_summary_says_why() -> None:
    with pytest.raises(CampaignError, match="world file not found"):
        parse_campaign(REFUSED_STDOUT)
    with pytest.raises(CampaignError, match="no JSON object"):
        parse_campaign("Traceback (most recent call last):\n")


def test_this_checkout_imports_its_own_packages_and_a_folder_without_them_is_refused(tmp_path: Path) -> None:
    assert checkout_problems(sys.executable, REPOSITORY) == []
    assert "not a checkout" in checkout_problems(sys.executable, tmp_path)[0]


def test_the_cpu_of_an_orphaned_grandchild_is_counted() -> None:
    # The child ends at once; the grandchild it leaves behind burns 0.3 s of CPU afterwards, as the
    # campaign's fork server does after the campaign's own process ended. It first waits 1.5 s: the
    # child's own start-up took 0.43 s on a loaded machine, longer than the 0.1 s it waited before.
    orphan = (
        "import os, time\n"
        "if os.fork() == 0:\n"
        "    os.close(1), os.close(2)\n"  # the child's output pipes do not wait for it
        "    time.sleep(1.5)\n"
        "    end = time.process_time() + 0.3\n"
        "    while time.process_time() < end:\n"
        "        pass\n"
    )
    measuring = (
        "import os, sys\n"
        "from pathlib import Path\n"
        "from sila_labware.benchmarks.interleaved_cpu import become_subreaper, measure\n"
        "become_subreaper()\n"
        f"done, cpu_s, wall_s = measure([sys.executable, '-c', {orphan!r}], Path.cwd(), dict(os.environ))\n"
        "print(cpu_s, wall_s)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", measuring], cwd=REPOSITORY, capture_output=True, text=True, timeout=30
    )
    assert done.returncode == 0, done.stderr
    cpu_s, wall_s = map(float, done.stdout.split())
    assert cpu_s >= 0.3
    assert wall_s < 1.5  # the child's own end: the orphan ran on after it
