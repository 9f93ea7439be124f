"""`bench --cluster ADDRESS`: the campaign's trials as Ray tasks, results streamed back as they end.

Why Ray: a campaign outgrows one machine; Ray places tasks on a cluster's nodes, and starts on a
laptop, on machines joined by `ray start` or on Kubernetes (KubeRay) alike. A trial stays what it is
with `--jobs` (ray_trial.py: a fresh deployment per trial, ports and ROS domain of its own on its
host), one CPU per task; results reach the same recorder as the workers' (workers.Recorder), so the
progress line, table, report and `--replay` lines are the same.

Faults of the cluster are not faults of the robot: Ray's own retries are off, so that each lost run
is seen here. A run whose node was lost (NodeDiedError) runs again elsewhere, up to
NODE_LOSSES_ALLOWED times, then the campaign ends with ClusterError; a run whose worker process died
on a live node is judged as `--jobs` judges one (workers.LOST_RUNS_ALLOWED: a second death is the
trial's own crash). Either way the outcome lists the lost runs (`lost_runs`, reported apart as
infrastructure). A cluster that cannot run the campaign (unreachable, no CPU for longer than
NO_CPU_GRACE_S) ends it with ClusterError.

Threads: the caller's (the CLI's main thread); Ray's own threads in the driver.
"""

from __future__ import annotations

import logging
import os
import shutil
import signal
import socket
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, redirect_stdout
from pathlib import Path
from typing import Any, TextIO

from sila_labware.benchmarks.campaign import (
    CampaignOptions,
    CampaignProgress,
    TrialOutcome,
    replay_flags,
)
from sila_labware.benchmarks.ray_trial import NodeResult, TrialFiles, run_trial_on_node
from sila_labware.benchmarks.workers import LOST_RUNS_ALLOWED, Recorder, log_levels, lost_trial

logger = logging.getLogger(__name__)

LOCAL = "local"
"""`--cluster local`: a one-node cluster started in this process, stopped with the campaign."""
AUTO = "auto"
"""`--cluster auto`: the cluster `ray start` runs on this machine (or RAY_ADDRESS)."""
NODE_LOSSES_ALLOWED = 3
"""Runs of one trial that may end with their node lost before the cluster is judged unable."""
NO_CPU_GRACE_S = 60.0
"""How long a cluster may offer no CPU (nodes joining, an autoscaler adding some) before giving up."""
CONNECT_TIMEOUT_S = 5.0
CANCEL_GRACE_S = 5.0
"""How long a cancelled trial has to stop its deployment before its Ray worker is killed."""
SILA2_ENVIRONMENT = ("PROTOCOL_BUFFERS_PYTHON_IMPLEMENTATION", "GRPC_ENABLE_FORK_SUPPORT")
LOCAL_OBJECT_STORE_BYTES = 100 * 1024 * 1024
"""A local cluster's object store: outcomes and one trial's frames, a few MB (Ray's floor is 75 MB)."""


class ClusterError(RuntimeError):
    """The cluster cannot run the campaign: unreachable, no nodes, nodes that cannot import or run a
    trial, or that keep getting lost."""


def check_reachable(address: str) -> None:
    """Fail fast for a HOST:PORT nobody answers on: Ray itself retries such an address for ever."""
    if address in (LOCAL, AUTO) or address.startswith("ray://"):
        return
    host, _, port = address.rpartition(":")
    if not host or not port.isdigit():
        raise ClusterError(f"--cluster {address}: expected HOST:PORT (the head's GCS), auto or local")
    try:
        socket.create_connection((host, int(port)), timeout=CONNECT_TIMEOUT_S).close()
    except OSError as error:
        raise ClusterError(f"no Ray cluster answers at {address}: {error}") from error


@contextmanager
def connected(address: str, local_cpus: int, verbose: bool = False) -> Iterator[None]:
    """Connect this process to the cluster at `address` (or start a local one with `local_cpus`
    CPUs), disconnect (and stop a local one) on the way out, whatever happens. Meanwhile this
    process's stdout is its stderr: Ray's threads print the cluster's news (a raylet that died) on
    stdout, which holds `bench --json`'s one object."""
    import ray

    check_reachable(address)
    with redirect_stdout(sys.stderr):
        yield from _connected(ray, address, local_cpus, verbose)


def _connected(ray: Any, address: str, local_cpus: int, verbose: bool) -> Iterator[None]:
    quiet = {"include_dashboard": False, "log_to_driver": verbose, "logging_level": logging.WARNING}
    scratch = None
    handlers = {number: signal.getsignal(number) for number in (signal.SIGINT, signal.SIGTERM)}
    try:
        if address == LOCAL:
            scratch = tempfile.mkdtemp(prefix="ray-")  # Ray's socket paths must stay short
            ray.init(  # "local": a new cluster even where `ray start` runs one (or RAY_ADDRESS names one)
                address=LOCAL,
                num_cpus=local_cpus,
                object_store_memory=LOCAL_OBJECT_STORE_BYTES,
                _temp_dir=scratch,
                **quiet,
            )
        else:
            ray.init(address=address, **quiet)
    except (ConnectionError, RuntimeError) as error:
        raise ClusterError(f"cannot connect to the Ray cluster at {address}: {error}") from error
    # Ray's core worker installs its own SIGTERM handler, which aborts the process: the bench's own
    # (stop the running trials, summarise the done ones, exit 130) come back.
    for number, handler in handlers.items():
        if handler is not None and threading.current_thread() is threading.main_thread():
            signal.signal(number, handler)
    try:
        yield
    finally:
        ray.shutdown()
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)


def run_cluster_campaign(
    options: CampaignOptions,
    address: str,
    progress_stream: TextIO | None = sys.stderr,
    on_trial: Callable[[TrialOutcome], None] | None = None,
) -> list[TrialOutcome]:
    """The campaign's trials on the Ray cluster at `address`; outcomes sorted by seed (fewer if
    stopped). Raises ClusterError when the cluster cannot run them."""
    verbose = logging.getLogger("sila_labware").isEnabledFor(logging.INFO)
    with connected(address, options.jobs, verbose):
        return _ClusterCampaign(options, progress_stream, on_trial).run()


class _ClusterCampaign:
    """The driver's side of one campaign: submit, wait for whichever trial ends, run lost ones again."""

    def __init__(
        self,
        options: CampaignOptions,
        progress_stream: TextIO | None,
        on_trial: Callable[[TrialOutcome], None] | None,
    ) -> None:
        import ray

        self._options = options
        self._levels = log_levels()
        self._outcomes: list[TrialOutcome] = []
        self._node_losses: dict[int, int] = {}
        progress = CampaignProgress(progress_stream, options.trials)
        self._report = Recorder(self._outcomes, progress, on_trial, replay_flags(options), {})
        self._task = ray.remote(num_cpus=1, max_retries=0, runtime_env={"env_vars": _sila2_environment()})(
            run_trial_on_node
        )
        self._running: dict[Any, int] = {}  # Ray object ref -> trial seed

    def run(self) -> list[TrialOutcome]:
        import ray

        _wait_for_a_cpu()
        for index in range(self._options.trials):
            self._submit(self._options.seed + index)
        try:
            while self._running:
                ready, _ = ray.wait(list(self._running), num_returns=1, timeout=NO_CPU_GRACE_S / 4)
                if not ready:
                    _wait_for_a_cpu()
                for ref in ready:
                    self._collect(ref, self._running.pop(ref))
        except KeyboardInterrupt:
            logger.warning(
                "interrupted: %d of %d trial(s) done; cancelling the running ones",
                len(self._outcomes), self._options.trials,
            )  # fmt: skip
            _cancel(list(self._running))
        return sorted(self._outcomes, key=lambda outcome: outcome.seed)

    def _submit(self, seed: int) -> None:
        options = self._options
        files = TrialFiles.of(options, seed)
        record = seed == options.seed and options.record_dir is not None
        self._running[self._task.remote(options, seed, files, record, self._levels)] = seed

    def _collect(self, ref: Any, seed: int) -> None:
        import ray
        from ray.exceptions import NodeDiedError, RayError, RayTaskError

        try:
            result: NodeResult = ray.get(ref)
        except RayTaskError as error:  # run_trial never raises for a failed trial: the node cannot run it
            raise ClusterError(
                f"trial seed {seed} could not run on its node (the same installation of sila-labware "
                f"on every node?): {_first_line(error.cause or error)}"
            ) from error
        except NodeDiedError as error:
            self._node_lost(seed, error)
            return
        except RayError as error:  # the worker process died under the trial on a live node
            self._worker_lost(seed, error)
            return
        if result.frames and self._options.record_dir is not None:
            _write_frames(self._options.record_dir, result.frames)
        self._report(result.outcome)

    def _node_lost(self, seed: int, error: Exception) -> None:
        losses = self._node_losses[seed] = self._node_losses.get(seed, 0) + 1
        self._report.lost_runs.setdefault(seed, []).append(f"node lost: {_first_line(error)}")
        if losses > NODE_LOSSES_ALLOWED:
            raise ClusterError(f"trial seed {seed} lost its node {losses} times: the cluster cannot run it")
        logger.warning("trial seed %d lost its node: it runs again elsewhere", seed)
        self._submit(seed)

    def _worker_lost(self, seed: int, error: Exception) -> None:
        runs = self._report.lost_runs.setdefault(seed, [])
        runs.append(f"worker lost: {_first_line(error)}")
        worker_deaths = sum(run.startswith("worker lost") for run in runs)
        if worker_deaths > LOST_RUNS_ALLOWED:
            self._report(lost_trial(seed, runs))
            return
        logger.warning("trial seed %d lost its worker process: it runs again", seed)
        self._submit(seed)


def _cancel(refs: list[Any]) -> None:
    """Stop running trials: a KeyboardInterrupt in each task first (its deployment stops on the way
    out), then its worker killed if it is still running after CANCEL_GRACE_S (a library may turn the
    interrupt into an error of its own and the trial run on); a robot side whose starter is gone stops
    by itself."""
    import ray

    for ref in refs:
        ray.cancel(ref)
    _, running = ray.wait(refs, num_returns=len(refs), timeout=CANCEL_GRACE_S)
    for ref in running:
        ray.cancel(ref, force=True)
    ray.wait(running, num_returns=len(running), timeout=CANCEL_GRACE_S)


def _sila2_environment() -> dict[str, str]:
    """The variables sila2 sets when imported, for the Ray workers to start with: they must be set
    before protobuf and gRPC are imported (sila2 builds its protobuf modules at import, which the
    C implementation refuses), and a Ray worker imports both before it runs a task."""
    import sila2  # noqa: F401 - sets them in this process

    return {name: os.environ[name] for name in SILA2_ENVIRONMENT}


def _wait_for_a_cpu() -> None:
    """Return once the cluster has a CPU; ClusterError when it offers none for NO_CPU_GRACE_S."""
    import ray

    deadline = time.monotonic() + NO_CPU_GRACE_S
    while ray.cluster_resources().get("CPU", 0.0) < 1.0:
        if time.monotonic() > deadline:
            raise ClusterError(
                f"the Ray cluster has had no CPU for {NO_CPU_GRACE_S:.0f} s: no node can run a trial"
            )
        time.sleep(1.0)


def _write_frames(record_dir: Path, frames: dict[str, bytes]) -> None:
    record_dir.mkdir(parents=True, exist_ok=True)
    for name, content in frames.items():
        (record_dir / name).write_bytes(content)


def _first_line(error: Exception) -> str:
    return (str(error).strip().splitlines() or [type(error).__name__])[0]
