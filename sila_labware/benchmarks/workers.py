"""`bench --jobs N`: trials side by side in N worker processes, results in seed order.

Why processes: a trial is a whole deployment (robot side, ROS bridge, SiLA servers) whose bridge
joins its ROS domain through this process's environment, so two trials cannot share a process.
Each worker runs one trial at a time with its own SiLA ports (`--port-base` + 10 per worker), its
own ROS domain (reserved per worker, whatever $ROS_DOMAIN_ID says, or `--domain-id` + the
worker index) and so its own robot
side; a trial's seed alone decides its disturbances and layout, whichever worker runs it.
Workers are spawned (not forked: the parent may hold threads and DDS state). Ctrl-C or SIGTERM:
the running trials are abandoned, each worker stops its deployment, the trials done are returned.

Threads: the caller's thread (the CLI's main thread) in the parent; each worker's main thread.
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import signal
import sys
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from typing import TextIO

from sila_labware.benchmarks.campaign import (
    CampaignOptions,
    CampaignProgress,
    TrialOutcome,
    record_outcome,
    replay_flags,
    run_trial,
)

logger = logging.getLogger(__name__)

_worker_index = 0  # in a worker process: its index, which sets its ports and ROS domain


def _start_worker(indices: multiprocessing.Queue, levels: dict[str, int]) -> None:
    """A worker's set-up: its index; a ROS domain of its own; logging as the parent's; signals
    unwind the running trial."""
    global _worker_index
    _worker_index = indices.get()
    # The parent's ROS_DOMAIN_ID would put every worker in one domain: without --domain-id each
    # worker reserves its own (ros_bridge.domain: a lock per id, held while the worker lives).
    os.environ.pop("ROS_DOMAIN_ID", None)
    from sila_labware.deployment.processes import interrupt_between_starts
    from sila_labware.servers.refusal_log import install_refusal_log_filter

    logging.basicConfig(format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    for name, level in levels.items():
        logging.getLogger(name or None).setLevel(level)
    install_refusal_log_filter()
    signal.signal(signal.SIGINT, interrupt_between_starts)
    signal.signal(signal.SIGTERM, interrupt_between_starts)


def _run_in_worker(options: CampaignOptions, trial_seed: int, record: bool) -> TrialOutcome:
    return run_trial(options, trial_seed, options.record_dir if record else None, worker=_worker_index)


def run_parallel_campaign(
    options: CampaignOptions,
    progress_stream: TextIO | None = sys.stderr,
    on_trial: Callable[[TrialOutcome], None] | None = None,
) -> list[TrialOutcome]:
    """The campaign's trials on `options.jobs` workers; outcomes sorted by seed (fewer if stopped)."""
    context = multiprocessing.get_context("spawn")
    indices = context.Queue()
    for index in range(options.jobs):
        indices.put(index)
    progress = CampaignProgress(progress_stream, options.trials)
    outcomes: list[TrialOutcome] = []
    levels = {name: logging.getLogger(name or None).getEffectiveLevel() for name in ("", "sila_labware")}
    pool = ProcessPoolExecutor(options.jobs, context, initializer=_start_worker, initargs=(indices, levels))
    futures: dict[Future[TrialOutcome], int] = {
        pool.submit(_run_in_worker, options, options.seed + index, index == 0): options.seed + index
        for index in range(options.trials)
    }
    try:
        for future in as_completed(futures):
            outcome = future.result()  # a worker's KeyboardInterrupt arrives here as one too
            record_outcome(outcome, outcomes, progress, on_trial, replay_flags(options))
    except KeyboardInterrupt:
        logger.warning(
            "interrupted: %d of %d trial(s) done; stopping the workers", len(outcomes), options.trials
        )
        for future in futures:
            future.cancel()
        for child in multiprocessing.active_children():  # each stops its deployment on the way out
            os.kill(child.pid, signal.SIGINT)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
    return sorted(outcomes, key=lambda outcome: outcome.seed)
