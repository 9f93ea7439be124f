"""`bench --jobs N`: trials side by side in N worker processes, results in seed order.

Why processes: a trial is a whole deployment (robot side, ROS bridge, SiLA servers) whose bridge
joins its ROS domain through this process's environment, so two trials cannot share a process.
Each worker runs one trial at a time with its own SiLA ports (`--port-base` + 10 per worker), its
own ROS domain (reserved per worker, whatever $ROS_DOMAIN_ID says, or `--domain-id` + the
worker index) and so its own robot
side; a trial's seed alone decides its disturbances and layout, whichever worker runs it.
Workers are spawned (not forked: the parent may hold threads and DDS state). Ctrl-C or SIGTERM:
the running trials are abandoned, each worker stops its deployment, the trials done are returned.
A worker that dies (a crash in a native library) breaks its pool: the trials running then (which of
them crashed it cannot be told) run once more, each alone in a pool of one worker, before the
trials not yet started go on in a fresh pool; their outcomes say so (`lost_runs`; the summary lists
them apart, as infrastructure). A trial whose worker dies under it when it runs alone fails
("other", "worker lost twice"): the trial itself crashes it, which is the software's fault, and its
replay shows it. So one crash costs the campaign neither the trials it hit nor the rest.

Threads: the caller's thread (the CLI's main thread) in the parent; each worker's main thread.
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import pickle
import signal
import sys
import tempfile
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, TextIO

from sila_labware.benchmarks.campaign import (
    CampaignOptions,
    CampaignProgress,
    TrialOutcome,
    record_outcome,
    replay_flags,
    run_trial,
)
from sila_labware.benchmarks.stop_deadline import STOP_DEADLINE_S

logger = logging.getLogger(__name__)

_worker_index = 0  # in a worker process: its index, which sets its ports and ROS domain
_started_dir = ""  # in a worker process: where it notes each trial it starts (a file per seed)


def log_levels() -> dict[str, int]:
    """The campaign's log levels, for `prepare_trial_process` in the processes that run its trials."""
    return {name: logging.getLogger(name or None).getEffectiveLevel() for name in ("", "sila_labware")}


def prepare_trial_process(levels: dict[str, int]) -> None:
    """Set up a process that runs trials one after the other (a worker here, a Ray worker): a ROS
    domain of its own, logging as the campaign's."""
    # The parent's ROS_DOMAIN_ID would put every worker in one domain: without --domain-id each
    # worker reserves its own (ros_bridge.domain: a lock per id, held while the worker lives).
    os.environ.pop("ROS_DOMAIN_ID", None)
    from sila_labware.servers.refusal_log import install_refusal_log_filter

    logging.basicConfig(format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    for name, level in levels.items():
        logging.getLogger(name or None).setLevel(level)
    install_refusal_log_filter()


def _start_worker(indices: multiprocessing.Queue, levels: dict[str, int], started_dir: str) -> None:
    """A worker's set-up: its index; a ROS domain of its own; logging as the parent's; signals
    unwind the running trial."""
    global _worker_index, _started_dir
    _worker_index, _started_dir = indices.get(), started_dir
    prepare_trial_process(levels)
    from sila_labware.deployment.processes import interrupt_between_starts

    signal.signal(signal.SIGINT, interrupt_between_starts)
    signal.signal(signal.SIGTERM, interrupt_between_starts)


def _run_in_worker(options: CampaignOptions, trial_seed: int, record: bool) -> TrialOutcome:
    record_dir = options.record_dir if record else None
    return run_trial(options, trial_seed, record_dir, worker=_worker_index, stop_deadline_s=STOP_DEADLINE_S)


def _noted(trial: Callable[..., TrialOutcome], options: CampaignOptions, seed: int, record: bool) -> Any:
    """Note on disk that this trial started, run it, and keep its outcome on disk too: both outlive
    a worker that dies, and a pool broken by another worker loses the results it had not yet passed
    on (a trial that ended then is not lost)."""
    (Path(_started_dir) / str(seed)).touch()
    outcome = trial(options, seed, record)
    (Path(_started_dir) / f"{seed}.outcome").write_bytes(pickle.dumps(outcome))
    return outcome


@dataclass(frozen=True)
class _Lost:
    """What the workers had noted when one died: the trials begun, the outcomes of those that ended."""

    begun: set[int]
    ended: dict[int, TrialOutcome]
    broken: BrokenProcessPool


def _noted_trials(started_dir: Path, broken: BrokenProcessPool) -> _Lost:
    """The seeds whose trials began, and the outcomes of those that ended, as the workers noted them."""
    begun = {int(path.name) for path in started_dir.iterdir() if path.name.isdigit()}
    ended = {int(path.stem): pickle.loads(path.read_bytes()) for path in started_dir.glob("*.outcome")}
    return _Lost(begun, ended, broken)


def lost_trial(trial_seed: int, lost_runs: list[str]) -> TrialOutcome:
    """The outcome of a trial whose worker died under it twice: a failure of cause "other"."""
    return TrialOutcome(
        seed=trial_seed,
        success=False,
        cause="other",
        error=f"worker lost twice: {lost_runs[-1]}",
        sim_seconds=0.0,
        wall_seconds=0.0,
        startup_wall_seconds=0.0,
        plate_position_error_mm=None,
        lost_runs=list(lost_runs),
    )


LOST_RUNS_ALLOWED = 1
"""Runs of one trial that may end in a dead worker before the trial counts as failed."""


def run_parallel_campaign(
    options: CampaignOptions,
    progress_stream: TextIO | None = sys.stderr,
    on_trial: Callable[[TrialOutcome], None] | None = None,
    trial: Callable[[CampaignOptions, int, bool], TrialOutcome] = _run_in_worker,
) -> list[TrialOutcome]:
    """The campaign's trials on `options.jobs` workers; outcomes sorted by seed (fewer if stopped).
    `trial` runs one trial in a worker (a module-level function, for the spawned workers)."""
    progress = CampaignProgress(progress_stream, options.trials)
    outcomes: list[TrialOutcome] = []
    levels = log_levels()
    waiting = [options.seed + index for index in range(options.trials)]
    lost_runs: dict[int, list[str]] = {}  # seed -> why each of its runs so far lost its worker
    report = Recorder(outcomes, progress, on_trial, replay_flags(options), lost_runs)
    while waiting:
        # a trial that lost its worker runs again alone: a second death then is its own
        again = [seed for seed in waiting if seed in lost_runs]
        if again:
            waiting = sorted(
                set(waiting) - {again[0]} | set(_run_pool(options, again[:1], levels, report, trial, 1))
            )
        else:
            waiting = _run_pool(options, waiting, levels, report, trial, options.jobs)
    return sorted(outcomes, key=lambda outcome: outcome.seed)


@dataclass
class Recorder:
    """Where finished trials go (see `record_outcome`), each with the runs of it a dead worker (or a
    lost cluster node, ray_campaign.py) lost."""

    outcomes: list[TrialOutcome]
    progress: CampaignProgress
    on_trial: Callable[[TrialOutcome], None] | None
    flags: str
    lost_runs: dict[int, list[str]]

    def __call__(self, outcome: TrialOutcome) -> None:
        lost = self.lost_runs.get(outcome.seed, [])
        if lost and not outcome.lost_runs:
            outcome = replace(outcome, lost_runs=list(lost))
        record_outcome(outcome, self.outcomes, self.progress, self.on_trial, self.flags)


def _run_pool(
    options: CampaignOptions,
    seeds: list[int],
    levels: dict[str, int],
    report: Recorder,
    trial: Callable[[CampaignOptions, int, bool], Any],
    jobs: int,
) -> list[int]:
    """Run `seeds` on a fresh pool of `jobs` workers; the seeds to run in the next one when a worker
    died (else none)."""
    context = multiprocessing.get_context("spawn")
    indices = context.Queue()
    for index in range(jobs):
        indices.put(index)
    started = tempfile.TemporaryDirectory(prefix="bench_started_")
    pool = ProcessPoolExecutor(
        jobs, context, initializer=_start_worker, initargs=(indices, levels, started.name)
    )
    futures: dict[Future[TrialOutcome], int] = {
        pool.submit(_noted, trial, options, seed, seed == options.seed): seed for seed in seeds
    }
    try:
        for future in as_completed(futures):
            try:
                outcome = future.result()  # a worker's KeyboardInterrupt arrives here as one too
            except BrokenProcessPool as broken:
                pool.shutdown(wait=True, cancel_futures=True)  # the other workers stopped: notes final
                lost = _noted_trials(Path(started.name), broken)
                return _after_a_lost_worker(futures, lost, report)
            report(outcome)
    except KeyboardInterrupt:
        logger.warning(
            "interrupted: %d of %d trial(s) done; stopping the workers", len(report.outcomes), options.trials
        )
        for future in futures:
            future.cancel()
        for child in multiprocessing.active_children():  # each stops its deployment on the way out
            os.kill(child.pid, signal.SIGINT)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        started.cleanup()
    return []


def _after_a_lost_worker(
    futures: dict[Future[TrialOutcome], int], lost: _Lost, report: Recorder
) -> list[int]:
    """A worker died: the trials that ended count; those that had begun and not ended run again (which
    of them crashed its worker cannot be told) unless a worker died under them before; the rest
    wait for a fresh pool too."""
    done = {outcome.seed for outcome in report.outcomes}
    waiting = []
    for future, seed in futures.items():
        if seed in done:
            continue
        if future.done() and not future.cancelled() and future.exception() is None:
            report(future.result())
        elif seed in lost.ended:
            report(lost.ended[seed])
        elif seed in lost.begun:
            runs = report.lost_runs.setdefault(seed, [])
            runs.append(f"worker lost: {lost.broken}")
            if len(runs) > LOST_RUNS_ALLOWED:
                report(lost_trial(seed, runs))
            else:
                logger.warning("trial seed %d lost its worker: it runs again", seed)
                waiting.append(seed)
        else:
            waiting.append(seed)
    logger.warning("a worker died (%s): %d trial(s) go on in a fresh pool", lost.broken, len(waiting))
    return sorted(waiting)
