"""A worker that dies mid-trial costs neither the trials it ran nor the campaign.

Why: a campaign worker once died in libc (a segfault) and the broken process pool ended all 200
trials; later, two trials of a 200-trial campaign failed as "worker lost" and delivered on replay.
Here trials really crash their worker process (SIGSEGV) on a real spawned pool; the trials are
stand-ins for deployments (seconds each otherwise), the pool and the crashes are real.
"""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

from sila_labware.benchmarks.campaign import (
    CampaignOptions,
    TrialOutcome,
    format_table,
    summarize,
)
from sila_labware.benchmarks.levels import default_level_values
from sila_labware.benchmarks.stop_deadline import stop_within
from sila_labware.benchmarks.workers import run_parallel_campaign
from sila_labware.deployment.stack import DeploymentOptions

SEED = 700
CRASHING_SEED = SEED + 2
TRIALS = 8


def crash_always(options: CampaignOptions, seed: int, _record: bool) -> TrialOutcome:
    """A trial that takes a moment; the one of CRASHING_SEED kills its worker as a segfault would,
    every time it runs (a trial that itself crashes the software)."""
    time.sleep(0.2)
    if seed == CRASHING_SEED:
        os.kill(os.getpid(), signal.SIGSEGV)
    return TrialOutcome(seed, True, "", "", 1.0, 0.2, 0.0, 1.0)


def crash_once(options: CampaignOptions, seed: int, _record: bool) -> TrialOutcome:
    """As `crash_always`, but the crash happens on the first run only (a machine's fault): a file
    beside the options' world file remembers it across the spawned workers."""
    marker = options.stack.world.with_name(f"crashed_{seed}")
    time.sleep(0.2)
    if seed == CRASHING_SEED and not marker.exists():
        marker.touch()
        os.kill(os.getpid(), signal.SIGSEGV)
    return TrialOutcome(seed, True, "", "", 1.0, 0.2, 0.0, 1.0)


def campaign(tmp_path: Path) -> CampaignOptions:
    return CampaignOptions(
        DeploymentOptions(world=tmp_path / "unused.yaml"), SEED, TRIALS, default_level_values(), jobs=2
    )


def test_a_trial_that_crashes_its_worker_twice_fails_and_the_campaign_goes_on(tmp_path: Path) -> None:
    options = campaign(tmp_path)
    outcomes = run_parallel_campaign(options, progress_stream=None, trial=crash_always)
    assert [outcome.seed for outcome in outcomes] == list(range(SEED, SEED + TRIALS))  # each reported once
    failed = [outcome for outcome in outcomes if not outcome.success]
    assert [outcome.seed for outcome in failed] == [CRASHING_SEED]
    assert failed[0].cause == "other" and failed[0].error.startswith("worker lost twice")
    assert len(failed[0].lost_runs) == 2
    # the trials that shared a pool with the crash ran again and delivered, marked as such
    assert all(outcome.success for outcome in outcomes if outcome.seed != CRASHING_SEED)


def test_a_trial_lost_once_runs_again_and_the_report_says_so(tmp_path: Path) -> None:
    options = campaign(tmp_path)
    outcomes = run_parallel_campaign(options, progress_stream=None, trial=crash_once)
    assert all(outcome.success for outcome in outcomes) and len(outcomes) == TRIALS
    rerun = {outcome.seed: outcome.lost_runs for outcome in outcomes if outcome.lost_runs}
    assert CRASHING_SEED in rerun and len(rerun[CRASHING_SEED]) == 1
    assert rerun[CRASHING_SEED][0].startswith("worker lost")
    summary = summarize(outcomes, options.levels, SEED)
    assert summary["successes"] == TRIALS
    assert CRASHING_SEED in {trial["seed"] for trial in summary["rerun_trials"]}
    assert "run again after their worker process died" in format_table(summary)


def hang_once_at_stop(options: CampaignOptions, seed: int, _record: bool) -> TrialOutcome:
    """As `crash_once`, but the first run hangs while it stops its deployment (as Fast DDS once spun
    for minutes destroying a participant): the campaign's stop deadline must end the worker."""
    marker = options.stack.world.with_name(f"hung_{seed}")
    if seed == CRASHING_SEED and not marker.exists():
        marker.touch()
        stop_within(lambda: time.sleep(60.0), deadline_s=1)
    return TrialOutcome(seed, True, "", "", 1.0, 0.2, 0.0, 1.0)


def test_a_trial_that_hangs_while_it_stops_is_ended_by_the_deadline_and_runs_again(tmp_path: Path) -> None:
    options = campaign(tmp_path)
    outcomes = run_parallel_campaign(options, progress_stream=None, trial=hang_once_at_stop)
    assert [outcome.seed for outcome in outcomes] == list(range(SEED, SEED + TRIALS))
    assert all(outcome.success for outcome in outcomes)
    hung = next(outcome for outcome in outcomes if outcome.seed == CRASHING_SEED)
    assert len(hung.lost_runs) == 1  # its worker was ended: a stop that had run its 60 s would not be
