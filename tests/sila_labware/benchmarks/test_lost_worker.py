"""A worker that dies mid-trial costs the trials it ran, not the campaign.

Why: a campaign worker once died in libc (a segfault) and the broken process pool ended all 200
trials. Here one trial really crashes its worker process (SIGSEGV) on a real spawned pool; the
trials are stand-ins for deployments (seconds each otherwise), the pool and the crash are real.
"""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

from sila_labware.benchmarks.campaign import CampaignOptions, TrialOutcome
from sila_labware.benchmarks.levels import default_level_values
from sila_labware.benchmarks.workers import run_parallel_campaign
from sila_labware.deployment.stack import DeploymentOptions

SEED = 700
CRASHING_SEED = SEED + 2


def crash_one(options: CampaignOptions, seed: int, _record: bool) -> TrialOutcome:
    """A trial that takes a moment; the one of CRASHING_SEED kills its worker as a segfault would."""
    time.sleep(0.2)
    if seed == CRASHING_SEED:
        os.kill(os.getpid(), signal.SIGSEGV)
    return TrialOutcome(seed, True, "", "", 1.0, 0.2, 0.0, 1.0)


def test_a_crashed_worker_fails_the_trials_it_ran_and_the_campaign_goes_on(tmp_path: Path) -> None:
    options = CampaignOptions(
        DeploymentOptions(world=tmp_path / "unused.yaml"), SEED, 8, default_level_values(), jobs=2
    )
    outcomes = run_parallel_campaign(options, progress_stream=None, trial=crash_one)
    assert [outcome.seed for outcome in outcomes] == list(range(SEED, SEED + 8))  # every trial reported once
    lost = [outcome for outcome in outcomes if not outcome.success]
    assert CRASHING_SEED in {outcome.seed for outcome in lost}
    assert all(outcome.cause == "other" and outcome.error.startswith("worker lost") for outcome in lost)
    assert len(lost) <= options.jobs  # only the trials running when it died (never re-run)
    assert sum(outcome.success for outcome in outcomes) >= 8 - options.jobs
