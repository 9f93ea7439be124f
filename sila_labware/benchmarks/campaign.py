"""Repeatability campaign: the demo transfer N times, each under its own seeded disturbances.

Why: field reports give task success as attempts/successes with failures by cause (navigation
drift, placements off by millimetres). This measures ours the same way, through the same SiLA
servers and the same standard command order as `sila-labware demo` (demo.run_demo).

One trial = a fresh deployment (sim node built from the trial seed's disturbed world, sequencer,
bridge, SiLA servers), the demo transfer, then stop: a fresh start (1.3 to 1.8 s against 5 s for
the transfer) keeps trials independent; a reset would also have to redraw what the robot believes.
Trial k of a campaign with seed S uses disturbance seed S + k, so `--replay S+k` runs it again alone: with
the same disturbances, not as the same run (the robot side's clock also runs, at 1x wall time,
while the robot software computes, so a replay's timing and contacts can differ; a failure that
does not come back on replay is not thereby explained).
Disturbance levels go to the sim node as JSON in SI units (tiago_sim.measuring.disturbances reads
them); here they are flags in mm, degrees and percent. Threads: the caller's (the CLI's main thread).
"""

from __future__ import annotations

import logging
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, TextIO

from sila_labware.benchmarks.failure_causes import CAUSES, classify_failure
from sila_labware.benchmarks.levels import levels_json
from sila_labware.benchmarks.stop_deadline import stop_within
from sila_labware.benchmarks.trial_logs import drop_if_delivered, trial_logs_dir
from sila_labware.client import remaining_time
from sila_labware.client.remaining_time import RemainingCheck
from sila_labware.deployment.demo import DemoReport, run_demo
from sila_labware.deployment.port_blocks import reserve_port_block
from sila_labware.deployment.processes import interrupt_requested
from sila_labware.deployment.stack import Deployment, DeploymentOptions

logger = logging.getLogger(__name__)


@dataclass
class TrialOutcome:
    seed: int
    success: bool
    cause: str  # "" on success, else one of CAUSES
    error: str
    sim_seconds: float
    wall_seconds: float
    startup_wall_seconds: float
    plate_position_error_mm: float | None
    steps: list[dict[str, Any]] = field(default_factory=list)
    world: str = ""  # the world file the trial ran in (a generated layout's, with --random-layouts)
    lost_runs: list[str] = field(default_factory=list)  # earlier runs whose worker or node died, and why
    remaining: list[dict[str, Any]] = field(default_factory=list)  # RemainingCheck per step, as dicts
    node: str = ""  # with --cluster: the host and Ray node that ran it (where, never what: not a result)


PORTS_PER_WORKER = 10  # SiLA ports a worker may use from its base: the robot's and up to 9 stations'


@dataclass
class CampaignOptions:
    stack: DeploymentOptions
    seed: int
    trials: int
    levels: dict[str, float]  # SI field name -> value in the flag's unit
    record_dir: Path | None = None  # frames of the first trial go here
    jobs: int = 1  # trials run side by side, each worker with its own robot side, ports and ROS domain
    layouts_dir: Path | None = None  # random layouts: trial seed S runs in layouts_dir/layout_S.yaml
    layouts_flag: str = "--random-layouts"  # the bench flag that drew them (for the replay line)
    real_robot: bool = False  # no lab-added sensors, Nav2's stop tolerances (bench --real-robot)
    failed_logs_dir: Path | None = None  # a failed trial's robot-side logs stay in trial_SEED here


def trial_stack(options: CampaignOptions, trial_seed: int, worker: int = 0) -> DeploymentOptions:
    """One trial's deployment: its world (random layout or the campaign's); the worker's own SiLA ports,
    ROS domain (a requested id shifted by the worker index) and CA file (a shared one let a client
    read another worker's CA and refuse its own servers); a robot side forked prewarmed."""
    extra = [
        *options.stack.extra_sim_arguments,
        *(["--stock-sensors"] if options.real_robot else []),
        "--disturbance-seed",
        str(trial_seed),
        "--disturbance-levels",
        levels_json(options.levels),
    ]
    layouts, domain_id, ca = options.layouts_dir, options.stack.domain_id, options.stack.ca_file
    return replace(
        options.stack,
        ca_file=ca if worker == 0 else ca.with_name(f"{ca.stem}-worker{worker}{ca.suffix}"),
        world=options.stack.world if layouts is None else layout_path(layouts, trial_seed),
        extra_sim_arguments=extra,
        port_base=options.stack.port_base + PORTS_PER_WORKER * worker,
        log_dir=trial_logs_dir(options.failed_logs_dir, trial_seed) or options.stack.log_dir,
        domain_id=None if domain_id is None else domain_id + worker,
        prewarmed_robot_side=True,
    )


def layout_path(layouts_dir: Path, trial_seed: int) -> Path:
    return layouts_dir / f"layout_{trial_seed}.yaml"


def run_trial(
    options: CampaignOptions,
    trial_seed: int,
    record_dir: Path | None = None,
    worker: int = 0,
    stop_deadline_s: int | None = None,
) -> TrialOutcome:
    """One fresh deployment, one standard transfer, stop. Never raises for a failed transfer.

    `stop_deadline_s` (a campaign's worker process only): if stopping the deployment takes longer,
    the kernel ends this process, which the campaign counts as a lost worker (`stop_deadline`)."""
    stack = trial_stack(options, trial_seed, worker)
    # reserved on the host, as tests and a Ray node's trials reserve theirs (`port_blocks`)
    stack = replace(stack, port_base=reserve_port_block(stack.port_base, PORTS_PER_WORKER, stack.host))
    if record_dir is not None:
        stack = replace(
            stack, extra_sim_arguments=[*stack.extra_sim_arguments, "--record-dir", str(record_dir)]
        )
    report, startup_s, start_failed = _run_once(stack, stop_deadline_s)
    lost_runs = []
    if start_failed and not interrupt_requested():
        # A robot side that never came up is the machine's fault, not the robot's (seen under load:
        # rclpy's node creation hung in DDS for the whole start-up's 180 s): once more in a fresh
        # deployment, and the outcome says so (`lost_runs`, listed apart in the table).
        logger.warning("trial seed %d %s; running it once more", trial_seed, report.error)
        lost_runs.append(report.error)
        report, startup_s, _ = _run_once(stack, stop_deadline_s)
    drop_if_delivered(stack.log_dir if options.failed_logs_dir is not None else None, report.success)
    cause = "" if report.success else classify_failure(report)
    return TrialOutcome(
        seed=trial_seed,
        success=report.success,
        cause=cause,
        error=report.error,
        sim_seconds=report.sim_seconds,
        wall_seconds=report.wall_seconds,
        startup_wall_seconds=startup_s,
        plate_position_error_mm=report.plate_position_error_mm,
        steps=[asdict(step) for step in report.steps],
        world=str(stack.world),
        remaining=[asdict(check) for check in report.remaining],
        lost_runs=lost_runs,
    )


def _run_once(stack: DeploymentOptions, stop_deadline_s: int | None) -> tuple[DemoReport, float, bool]:
    """One deployment's start, transfer and stop: its report, start-up seconds and whether the start
    itself failed."""
    deployment = Deployment(stack)
    started = time.monotonic()
    start_failed = True
    try:
        deployment.start()
        start_failed = False
        startup_s = time.monotonic() - started
        report = run_demo(deployment, progress_stream=None)
    except Exception as error:  # noqa: BLE001 - a trial that cannot even start is an "other" failure
        startup_s = time.monotonic() - started
        report = DemoReport(error=f"could not start: {type(error).__name__}: {error}")
    finally:
        stop_within(deployment.stop, stop_deadline_s)
    return report, startup_s, start_failed


class CampaignProgress:
    """A progress bar on a terminal; one line per trial otherwise."""

    def __init__(self, stream: TextIO | None, total: int) -> None:
        self._stream = stream
        self._total = total
        self._interactive = bool(stream is not None and stream.isatty())
        self._started = time.monotonic()

    def update(self, outcomes: list[TrialOutcome]) -> None:
        if self._stream is None or not outcomes:
            return
        done, last = len(outcomes), outcomes[-1]
        successes = sum(outcome.success for outcome in outcomes)
        elapsed = time.monotonic() - self._started
        eta = elapsed / done * (self._total - done)
        filled = int(round(30 * done / self._total))
        counts = f"{done}/{self._total} ok {successes} failed {done - successes}"
        bar = f"[{'#' * filled}{'.' * (30 - filled)}] {counts}"
        if self._interactive:
            self._stream.write(f"\r{bar}  {eta / 60:5.1f} min left ")
            if done == self._total:
                self._stream.write("\n")
        else:
            verdict = "ok" if last.success else f"FAILED ({last.cause})"
            self._stream.write(f"{bar}: seed {last.seed} {verdict}, {last.sim_seconds:.1f} s sim\n")
        self._stream.flush()


def run_campaign(
    options: CampaignOptions,
    progress_stream: TextIO | None = sys.stderr,
    on_trial: Callable[[TrialOutcome], None] | None = None,
) -> list[TrialOutcome]:
    """Trials with seeds seed, seed+1, ...; a failure is logged with its seed and the campaign goes on.

    Ctrl-C (or SIGTERM, see the CLI) abandons the running trial, whose robot side and servers are
    stopped on the way out, and returns the trials done so far: fewer than asked for."""
    progress = CampaignProgress(progress_stream, options.trials)
    outcomes: list[TrialOutcome] = []
    for index in range(options.trials):
        trial_seed = options.seed + index
        record_dir = options.record_dir if index == 0 else None
        try:
            outcome = run_trial(options, trial_seed, record_dir)
            if interrupt_requested():  # a library turned the KeyboardInterrupt into its own error
                raise KeyboardInterrupt
        except KeyboardInterrupt:
            logger.warning(
                "interrupted: trial seed %d abandoned, %d of %d trial(s) done",
                trial_seed, len(outcomes), options.trials,
            )  # fmt: skip
            break
        record_outcome(outcome, outcomes, progress, on_trial, replay_flags(options))
    return outcomes


def replay_flags(options: CampaignOptions) -> str:
    """What `bench --replay SEED` needs besides the seed to run a trial of this campaign again."""
    world = f" --world {options.stack.world}" if options.layouts_flag == "--random-obstacles" else ""
    layouts = f" {options.layouts_flag}{world}" if options.layouts_dir is not None else ""
    pace = f" --pace {options.stack.pace:g}" if options.stack.pace is not None else ""
    return layouts + (" --real-robot" if options.real_robot else "") + pace


def record_outcome(
    outcome: TrialOutcome,
    outcomes: list[TrialOutcome],
    progress: CampaignProgress,
    on_trial: Callable[[TrialOutcome], None] | None,
    flags: str = "",
) -> None:
    """A finished trial: its failure logged with how to replay it, the progress shown, the callback."""
    if not outcome.success:
        logger.warning(
            "trial seed %d failed (%s): %s; same disturbances again: sila-labware bench --replay %d%s",
            outcome.seed, outcome.cause, outcome.error, outcome.seed, flags,
        )  # fmt: skip
    outcomes.append(outcome)
    progress.update(outcomes)
    if on_trial is not None:
        on_trial(outcome)


def _median(values: list[float]) -> float:
    return float(statistics.median(values)) if values else 0.0


def summarize(outcomes: list[TrialOutcome], levels: dict[str, float], seed: int) -> dict[str, Any]:
    """The success table and timings as one JSON-ready object."""
    successes = sum(outcome.success for outcome in outcomes)
    timed = [outcome for outcome in outcomes if outcome.success] or outcomes
    failures = {cause: sum(outcome.cause == cause for outcome in outcomes) for cause in CAUSES}
    sim_total = sum(outcome.sim_seconds for outcome in outcomes)
    wall_total = sum(outcome.wall_seconds for outcome in outcomes)
    phase_names = list(dict.fromkeys(step["name"] for outcome in outcomes for step in outcome.steps))
    phases = {
        name: {
            "sim_seconds_median": _median(
                [s["sim_seconds"] for o in outcomes for s in o.steps if s["name"] == name]
            ),
            "wall_seconds_median": _median(
                [s["wall_seconds"] for o in outcomes for s in o.steps if s["name"] == name]
            ),
        }
        for name in phase_names
    }
    delivered = [
        o.plate_position_error_mm for o in outcomes if o.success and o.plate_position_error_mm is not None
    ]
    return {
        "seed": seed,
        "trials": len(outcomes),
        "successes": successes,
        "success_rate": successes / len(outcomes) if outcomes else 0.0,
        "failures": failures,
        # per delivered transfer (a failed trial stops early); all trials if none was delivered
        "sim_seconds_median": _median([o.sim_seconds for o in timed]),
        "wall_seconds_median": _median([o.wall_seconds for o in timed]),
        "startup_wall_seconds_median": _median([o.startup_wall_seconds for o in outcomes]),
        "sim_seconds_total": sim_total,
        "wall_seconds_total": wall_total,
        "campaign_wall_seconds": wall_total + sum(o.startup_wall_seconds for o in outcomes),
        "realtime_factor": sim_total / wall_total if wall_total > 0 else 0.0,
        "placement_error_mm_median": _median(delivered),
        "placement_error_mm_max": max(delivered, default=0.0),
        "phases": phases,
        "failed_trials": [
            {"seed": o.seed, "cause": o.cause, "error": o.error, "world": o.world}
            for o in outcomes
            if not o.success
        ],
        "remaining_time": remaining_time.summary(
            [RemainingCheck.from_dict(check) for outcome in outcomes for check in outcome.remaining]
        ),
        # infrastructure, not the robot: trials run again because their worker process or node died
        "rerun_trials": [{"seed": o.seed, "lost_runs": o.lost_runs} for o in outcomes if o.lost_runs],
        "levels": levels,
        "outcomes": [asdict(o) for o in outcomes],
    }


def format_table(summary: dict[str, Any]) -> str:
    """The success table and timings as text (Markdown-compatible)."""
    lines = [
        "| attempts | successes | success rate | " + " | ".join(CAUSES) + " |",
        "|---:|---:|---:|" + "---:|" * len(CAUSES),
        f"| {summary['trials']} | {summary['successes']} | {100 * summary['success_rate']:.1f} % | "
        + " | ".join(str(summary["failures"][cause]) for cause in CAUSES)
        + " |",
        "",
        "| phase | simulated s (median) | wall s (median) |",
        "|---|---:|---:|",
    ]
    for name, phase in summary["phases"].items():
        lines.append(f"| {name} | {phase['sim_seconds_median']:.1f} | {phase['wall_seconds_median']:.1f} |")
    lines.append(
        f"| whole transfer (delivered) | {summary['sim_seconds_median']:.1f} | "
        f"{summary['wall_seconds_median']:.1f} |"
    )
    lines += [
        "",
        f"total: {summary['sim_seconds_total']:.0f} s simulated, {summary['wall_seconds_total']:.0f} s wall "
        f"in transfers (real-time factor {summary['realtime_factor']:.1f}); campaign wall time including "
        f"a fresh start per trial ({summary['startup_wall_seconds_median']:.1f} s median): "
        f"{summary['campaign_wall_seconds']:.0f} s",
        f"placement error of delivered plates: median {summary['placement_error_mm_median']:.1f} mm, "
        f"max {summary['placement_error_mm_max']:.1f} mm",
    ]
    # unpaced, no wall-time estimate can hold (the summary says so)
    estimates = summary.get("remaining_time")
    if estimates and estimates.get("steps") and summary.get("pace"):
        worst = min(estimates["by_step"].items(), key=lambda item: item[1])
        lines.append(
            f"remaining-time estimates within {100 * estimates['tolerance']:.0f} % of the step at each "
            f"quarter: {estimates['within']} of {estimates['steps']} steps "
            f"({100 * estimates['share_within']:.1f} %); least often: {worst[0]} ({100 * worst[1]:.0f} %)"
        )
    reruns = summary.get("rerun_trials", [])
    if reruns:
        seeds = ", ".join(str(rerun["seed"]) for rerun in reruns)
        lines.append(
            f"run again after their worker process died, their cluster node was lost or their robot side "
            f"did not start (infrastructure, not counted as failures): "
            f"{len(reruns)} trial(s), seeds {seeds}"
        )
    if "elapsed_wall_seconds" in summary and summary["trials"]:
        elapsed = summary["elapsed_wall_seconds"]
        cluster = summary.get("cluster")
        where = f"the Ray cluster {cluster}" if cluster else f"{summary['jobs']} worker(s)"
        lines.append(
            f"elapsed: {elapsed:.0f} s for {summary['trials']} trial(s) on {where}, "
            f"{elapsed / summary['trials']:.1f} s per trial"
        )
    for failed in summary["failed_trials"]:
        lines.append(f"failed: seed {failed['seed']} ({failed['cause']}): {failed['error']}")
    return "\n".join(lines)


def format_targets(summary: dict[str, Any]) -> str:
    """The issue's targets against what was measured (printed, never asserted)."""
    wall_ratio = (
        summary["wall_seconds_median"] / summary["sim_seconds_median"]
        if summary["sim_seconds_median"]
        else 0.0
    )

    enough = summary["success_rate"] >= 0.99 and summary["trials"] >= 200

    def verdict(met: bool) -> str:
        return "met" if met else "NOT met"

    return "\n".join(
        [
            f"target >= 99 % success over 200 trials: {100 * summary['success_rate']:.1f} % over "
            f"{summary['trials']} trials ({verdict(enough)})",
            f"target <= 60 s simulated per transfer: {summary['sim_seconds_median']:.1f} s median "
            f"({verdict(summary['sim_seconds_median'] <= 60.0)})",
            f"target wall <= 1/10 of simulated: {wall_ratio:.3f} ({verdict(0 < wall_ratio <= 0.1)})",
        ]
    )
