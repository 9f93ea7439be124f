"""`sila-labware bench`: arguments and the command; `demo --record`: pictures of one run.

    sila-labware bench --trials N --seed S [--world FILE | --random-layouts] [--json]
                       [--jobs N | --cluster ADDRESS] [--report DIR] [--replay SEED] [--level-scale X]
                       [--nav-error-mm MM ...one flag per disturbance level]
    sila-labware bench --save-layout SEED FILE

Exit codes: 0 every trial delivered its plate, 1 at least one failed, 2 bad usage, 130 stopped by
Ctrl-C or SIGTERM (the trials done so far are still summarised). Threads: the CLI's main thread.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from sila_labware.benchmarks import trial_logs
from sila_labware.benchmarks.campaign import (
    PORTS_PER_WORKER,
    CampaignOptions,
    TrialOutcome,
    format_table,
    format_targets,
    run_campaign,
    summarize,
)
from sila_labware.benchmarks.levels import LEVEL_FLAGS, REAL_ROBOT_LEVELS
from sila_labware.benchmarks.random_layouts import (
    LayoutGenerationError,
    generate_layouts,
    keep_failed_layouts,
    save_layout,
)
from sila_labware.benchmarks.ray_campaign import ClusterError, run_cluster_campaign
from sila_labware.benchmarks.workers import run_parallel_campaign
from sila_labware.client.remaining_time import NOT_JUDGED_UNPACED
from sila_labware.deployment import json_outcome
from sila_labware.deployment.json_outcome import JsonOutput, outcome_fields
from sila_labware.deployment.stack import DeploymentOptions

logger = logging.getLogger(__name__)

INTERRUPTED_EXIT_CODE = 130  # the shell's code for a command ended by SIGINT
# What a replay repeats, said wherever one is offered or run: the robot side's clock also runs while
# the robot software computes (at the idle robot's pace, 1x wall time), so when a motion starts in
# simulated time, and with it every later contact, depends on the machine's load.
REPLAY_REPEATS = (
    "the same disturbances (every drawn error and noise seed), not the same run: simulated time "
    "also passes while the robot software computes, at wall-clock pace, so the trace can differ"
)


def add_bench_arguments(bench: argparse.ArgumentParser) -> None:
    """Campaign options and one flag per disturbance level (defaults: the documented default level)."""
    bench.add_argument("--trials", type=int, default=30, help="number of transfers (default: %(default)s)")
    bench.add_argument("--seed", type=int, default=1, help="trial k uses disturbance seed SEED+k")
    bench.add_argument(
        "--replay",
        type=int,
        default=None,
        metavar="SEED",
        help=f"run the one trial with SEED again: {REPLAY_REPEATS}",
    )
    bench.add_argument(
        "--random-layouts",
        action="store_true",
        help="a new random lab per trial, drawn from the trial seed (--world is not used); "
        "failed trials' world files are written next to the --report",
    )
    bench.add_argument(
        "--random-obstacles",
        action="store_true",
        help="the campaign's world (--world) with 1 to 3 random obstacles per trial near its drives, "
        "drawn from the trial seed; failed trials' world files are written next to the --report",
    )
    bench.add_argument(
        "--save-layout",
        nargs=2,
        metavar=("SEED", "FILE"),
        default=None,
        help="write the random layout of trial seed SEED to FILE (for demo --world) and exit; with "
        "--random-obstacles, the world with that seed's obstacles",
    )
    bench.add_argument(
        "--jobs",
        type=int,
        default=None,  # the cores this process may run on (validate_bench), unless --cluster
        help="trials run side by side, each with its own robot side, SiLA ports (--port-base + 10 per "
        f"worker) and ROS domain (default: the cores, {len(os.sched_getaffinity(0))})",
    )
    bench.add_argument(
        "--cluster",
        default=None,
        metavar="ADDRESS",
        help="run the trials as tasks on a Ray cluster: HOST:PORT of its head, 'auto' (the cluster "
        "`ray start` runs on this machine) or 'local' (one started here, on the cores); each trial "
        "takes one CPU and reserves its SiLA ports (from --port-base) and ROS domain on its host",
    )
    bench.add_argument("--json", action="store_true", help="print one JSON object with the results")
    bench.add_argument(
        "--report",
        type=Path,
        default=None,
        metavar="DIR",
        help="write PNG charts, run pictures and the failed trials' robot-side logs (failed-trial-logs/)",
    )
    bench.add_argument(
        "--level-scale", type=float, default=1.0, help="multiply every default level (0: no disturbance)"
    )
    bench.add_argument(
        "--real-robot",
        action="store_true",
        help="a real TIAGo++'s conditions: no lab-added sensors (--stock-sensors) and navigation "
        "stopping anywhere Nav2's default goal checker allows (0.25 m, 0.25 rad; sets --nav-error-mm "
        "and --nav-error-deg unless given)",
    )
    levels = bench.add_argument_group("disturbance levels (one standard deviation each)")
    for level in LEVEL_FLAGS:
        levels.add_argument(
            level.flag, dest=f"level_{level.field}", type=float, default=None, metavar="X",
            help=f"{level.help} (default: {level.default:g})",
        )  # fmt: skip


def validate_bench(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    if args.trials < 1:
        parser.error(f"--trials {args.trials}: need at least one")
    if args.cluster is not None:
        for flag, given in (("--jobs", args.jobs is not None), ("--domain-id", args.domain_id is not None)):
            if given:
                parser.error(f"--cluster and {flag} exclude each other (the cluster places the trials)")
    if args.jobs is None:
        args.jobs = len(os.sched_getaffinity(0))
    if args.jobs < 1:
        parser.error(f"--jobs {args.jobs}: need at least one")
    if args.port_base + PORTS_PER_WORKER * args.jobs > 65535:
        parser.error(f"--port-base {args.port_base} leaves no room for {args.jobs} workers' ports")
    if args.save_layout is not None:
        seed, _file = args.save_layout
        if not seed.lstrip("-").isdigit():
            parser.error(f"--save-layout {seed}: the seed is an integer")
    if args.random_layouts and args.random_obstacles:
        parser.error(
            "--random-layouts and --random-obstacles exclude each other (a random lab has no --world)"
        )
    if args.level_scale < 0:
        parser.error("--level-scale must not be negative")
    for level in LEVEL_FLAGS:
        value = getattr(args, f"level_{level.field}")
        if value is not None and value < 0:
            parser.error(f"{level.flag} must not be negative")


def level_values(args: argparse.Namespace) -> dict[str, float]:
    """Field -> value in the flag's unit: an explicit flag wins over default times --level-scale."""
    values = {}
    for level in LEVEL_FLAGS:
        given = getattr(args, f"level_{level.field}")
        if given is None and getattr(args, "real_robot", False):
            given = REAL_ROBOT_LEVELS.get(level.field)
        values[level.field] = given if given is not None else level.default * args.level_scale
    return values


def bench_command(args: argparse.Namespace, stack: DeploymentOptions) -> int:
    """Run the campaign (or one replayed trial), print the table or JSON, write the report."""
    if not args.verbose:
        # sila2 logs every failed command as a server-side traceback under loggers named after the
        # feature or command; the bench's own log (failures with their seeds) stays visible.
        logging.getLogger().setLevel(logging.CRITICAL)
        logging.getLogger("sila_labware").setLevel(logging.WARNING)
    if args.save_layout is not None:
        furnish = stack.world if args.random_obstacles else None
        return save_layout_command(int(args.save_layout[0]), Path(args.save_layout[1]), furnish, args.json)
    levels = level_values(args)
    first_seed, trials = (args.replay, 1) if args.replay is not None else (args.seed, args.trials)
    frames_dir = args.report / "frames" if args.report is not None else None
    # A trial's client connects to its servers by address: mDNS registration took 5 of a trial's
    # 9 s start-up (measured), so a bench serves without discovery.
    stack = replace(stack, discovery=False)
    jobs = min(args.jobs, trials)
    options = CampaignOptions(
        stack, first_seed, trials, levels, record_dir=frames_dir, jobs=jobs, real_robot=args.real_robot
    )
    with tempfile.TemporaryDirectory(prefix="sila-labware-layouts-") as scratch:
        if args.random_layouts or args.random_obstacles:
            furnish = stack.world if args.random_obstacles else None
            try:
                options.layouts_dir = draw_layouts(first_seed, trials, Path(scratch), jobs, furnish)
            except LayoutGenerationError as error:
                sys.stderr.write(f"bench: no random layouts: {error}\n")
                if args.json:
                    JsonOutput.write_failure(f"no random layouts: {error}", json_outcome.START_FAILED, 1)
                return 1
            if args.random_obstacles:
                options.layouts_flag = "--random-obstacles"
        return _run_and_report(args, options)


def draw_layouts(
    first_seed: int, trials: int, directory: Path, jobs: int, furnish: Path | None = None
) -> Path:
    """The campaign's random layouts (or `furnish` with random obstacles), one per trial seed,
    written before the first trial."""
    seeds = list(range(first_seed, first_seed + trials))
    what = "random layout(s)" if furnish is None else f"obstacle set(s) for {furnish}"
    sys.stderr.write(f"bench: drawing {trials} {what}\n")
    generate_layouts(seeds, directory, jobs, furnish)
    return directory


def save_layout_command(seed: int, target: Path, furnish: Path | None = None, as_json: bool = False) -> int:
    """Write one seed's layout; with `as_json` the outcome is one JSON object (`layout`: the file)."""
    try:
        save_layout(seed, target, furnish)
    except LayoutGenerationError as error:
        sys.stderr.write(f"bench: {error}\n")
        if as_json:
            JsonOutput.write_failure(str(error), json_outcome.FAILED, 1)
        return 1
    what = (
        f"random layout of seed {seed}" if furnish is None else f"{furnish} with the obstacles of seed {seed}"
    )
    if as_json:
        JsonOutput.write({"layout": str(target), "seed": seed, **outcome_fields()})
    else:
        sys.stdout.write(f"{target}: {what}; run it with sila-labware demo --world {target}\n")
    return 0


def _run_and_report(args: argparse.Namespace, options: CampaignOptions) -> int:
    from sila_labware.benchmarks.campaign_report import write_charts, write_run_pictures

    levels, first_seed, trials, frames_dir = options.levels, options.seed, options.trials, options.record_dir
    if args.replay is not None:
        sys.stderr.write(f"bench: replaying seed {first_seed}: {REPLAY_REPEATS}\n")
    else:
        sys.stderr.write(f"bench: {trials} trial(s) from seed {first_seed}\n")
    on_trial = None
    if args.report is not None:
        args.report.mkdir(parents=True, exist_ok=True)
        if args.cluster is None and args.log_dir is None:  # on a cluster a node's files stay there
            options.failed_logs_dir = args.report / trial_logs.FOLDER
        trials_log = args.report / "trials.jsonl"
        trials_log.write_text("")

        def on_trial(outcome: TrialOutcome) -> None:  # a campaign cut short still leaves its trials
            with trials_log.open("a") as log_file:
                log_file.write(json.dumps(asdict(outcome)) + "\n")

    started = time.monotonic()
    try:
        outcomes = _run(args.cluster, options, on_trial)
    except ClusterError as error:
        sys.stderr.write(f"bench: {error}\n")
        if args.json:
            JsonOutput.write_failure(str(error), json_outcome.START_FAILED, 1)
        return 1
    elapsed_s = time.monotonic() - started
    kept = []
    if args.report is not None and options.layouts_dir is not None:
        kept = keep_failed_layouts(outcomes, args.report)  # the temporary layouts go with the run
    shown_levels = {level.flag.removeprefix("--"): levels[level.field] for level in LEVEL_FLAGS}
    summary = summarize(outcomes, shown_levels, first_seed)
    summary["jobs"] = options.jobs
    summary["cluster"] = args.cluster  # None: the trials ran on this machine's workers
    summary["pace"] = options.stack.pace  # None: unpaced, where the remaining times are not judged
    if options.stack.pace is None:
        summary["remaining_time"] = {"judged": False, "why": NOT_JUDGED_UNPACED}
    summary["random_layouts"] = options.layouts_dir is not None and options.layouts_flag == "--random-layouts"
    summary["random_obstacles"] = (
        options.layouts_dir is not None and options.layouts_flag == "--random-obstacles"
    )
    summary["elapsed_wall_seconds"] = elapsed_s  # the trials' own, from the first start to the last stop
    if args.report is not None:
        written = write_charts(summary, args.report)
        written += write_run_pictures(frames_dir, args.report) + kept
        written += trial_logs.kept_trial_logs(options.failed_logs_dir)
        (args.report / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
        sys.stderr.write("report: " + ", ".join(str(path) for path in written) + "\n")
    interrupted = len(outcomes) < trials
    if interrupted:
        summary["interrupted_after_trials"] = len(outcomes)
    if args.replay is not None:
        summary["replay_repeats"] = REPLAY_REPEATS
    all_delivered = summary["successes"] == summary["trials"]
    exit_code = INTERRUPTED_EXIT_CODE if interrupted else 0 if all_delivered else 1
    if args.json:
        JsonOutput.write({**summary, **_outcome(summary, trials, exit_code)})
    else:
        if interrupted:
            sys.stdout.write(f"interrupted: {len(outcomes)} of {trials} trial(s) done\n")
        sys.stdout.write(format_table(summary) + "\n\n" + format_targets(summary) + "\n")
        if args.replay is not None:
            sys.stdout.write(f"replayed: {REPLAY_REPEATS}\n")
    return exit_code


def _run(
    cluster: str | None, options: CampaignOptions, on_trial: Callable[[TrialOutcome], None] | None
) -> list[TrialOutcome]:
    """The campaign's trials in this process, on workers, or on a Ray cluster."""
    if cluster is not None:
        return run_cluster_campaign(options, cluster, progress_stream=sys.stderr, on_trial=on_trial)
    run = run_campaign if options.jobs == 1 else run_parallel_campaign
    return run(options, progress_stream=sys.stderr, on_trial=on_trial)


def _outcome(summary: dict[str, Any], trials: int, exit_code: int) -> dict[str, Any]:
    """The machine-readable outcome fields (json_outcome) of a campaign's summary."""
    if exit_code == INTERRUPTED_EXIT_CODE:
        error = f"interrupted (SIGINT or SIGTERM) after {summary['trials']} of {trials} trial(s)"
        return outcome_fields(error, json_outcome.INTERRUPTED, exit_code)
    if exit_code:
        error = f"{summary['trials'] - summary['successes']} of {summary['trials']} trial(s) failed"
        return outcome_fields(error, json_outcome.FAILED, exit_code)
    return outcome_fields()


def write_recorded_pictures(record_dir: Path) -> None:
    """After `demo --record DIR`: the strip and GIF from the frames the sim node saved."""
    from sila_labware.benchmarks.campaign_report import write_run_pictures

    written = write_run_pictures(record_dir / "frames", record_dir)
    sys.stderr.write("pictures: " + ", ".join(str(path) for path in written) + "\n")
