"""A failed campaign trial's robot-side logs, kept beside the report; a delivered trial's dropped.

Why: a failure that does not come back on replay (the robot side's clock runs at wall time while the
software computes, so a replay's timing differs) can only be read from the run that failed. Every
trial writes its logs into `trial_SEED` of the report's `failed-trial-logs` folder; a delivered
trial's folder is removed as the trial ends, so a campaign keeps only what it needs to explain.
"""

from __future__ import annotations

import shutil
from pathlib import Path

FOLDER = "failed-trial-logs"


def trial_logs_dir(failed_logs_dir: Path | None, trial_seed: int) -> Path | None:
    """Where trial `trial_seed` writes its logs (None: the logs are not kept)."""
    return None if failed_logs_dir is None else failed_logs_dir / f"trial_{trial_seed}"


def drop_if_delivered(log_dir: Path | None, success: bool) -> None:
    if log_dir is not None and success:
        shutil.rmtree(log_dir, ignore_errors=True)


def kept_trial_logs(failed_logs_dir: Path | None) -> list[Path]:
    """The folders of the failed trials' logs (for the report's list of what it wrote)."""
    if failed_logs_dir is None or not failed_logs_dir.is_dir():
        return []
    return sorted(path for path in failed_logs_dir.iterdir() if path.is_dir())
