"""`sila-labware bench`: arguments and the command; `demo --record`: pictures of one run.

    sila-labware bench --trials N --seed S [--world FILE] [--json] [--report DIR] [--replay SEED]
                       [--level-scale X] [--nav-error-mm MM ...one flag per disturbance level]

Exit codes: 0 every trial delivered its plate, 1 at least one failed, 2 bad usage, 130 stopped by
Ctrl-C or SIGTERM (the trials done so far are still summarised). Threads: the CLI's main thread.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from dataclasses import asdict
from pathlib import Path

from sila_labware.benchmarks.campaign import (
    LEVEL_FLAGS,
    CampaignOptions,
    TrialOutcome,
    format_table,
    format_targets,
    run_campaign,
    summarize,
)
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
    bench.add_argument("--json", action="store_true", help="print one JSON object with the results")
    bench.add_argument(
        "--report", type=Path, default=None, metavar="DIR", help="write PNG charts and run pictures"
    )
    bench.add_argument(
        "--level-scale", type=float, default=1.0, help="multiply every default level (0: no disturbance)"
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
        values[level.field] = given if given is not None else level.default * args.level_scale
    return values


def bench_command(args: argparse.Namespace, stack: DeploymentOptions) -> int:
    """Run the campaign (or one replayed trial), print the table or JSON, write the report."""
    from sila_labware.benchmarks.campaign_report import write_charts, write_run_pictures

    if not args.verbose:
        # sila2 logs every failed command as a server-side traceback under loggers named after the
        # feature or command; the bench's own log (failures with their seeds) stays visible.
        logging.getLogger().setLevel(logging.CRITICAL)
        logging.getLogger("sila_labware").setLevel(logging.WARNING)
    levels = level_values(args)
    first_seed, trials = (args.replay, 1) if args.replay is not None else (args.seed, args.trials)
    frames_dir = args.report / "frames" if args.report is not None else None
    options = CampaignOptions(stack, first_seed, trials, levels, record_dir=frames_dir)
    if args.replay is not None:
        sys.stderr.write(f"bench: replaying seed {first_seed}: {REPLAY_REPEATS}\n")
    else:
        sys.stderr.write(f"bench: {trials} trial(s) from seed {first_seed}\n")
    on_trial = None
    if args.report is not None:
        args.report.mkdir(parents=True, exist_ok=True)
        trials_log = args.report / "trials.jsonl"
        trials_log.write_text("")

        def on_trial(outcome: TrialOutcome) -> None:  # a campaign cut short still leaves its trials
            with trials_log.open("a") as log_file:
                log_file.write(json.dumps(asdict(outcome)) + "\n")

    outcomes = run_campaign(options, progress_stream=sys.stderr, on_trial=on_trial)
    shown_levels = {level.flag.removeprefix("--"): levels[level.field] for level in LEVEL_FLAGS}
    summary = summarize(outcomes, shown_levels, first_seed)
    if args.report is not None:
        written = write_charts(summary, args.report)
        written += write_run_pictures(frames_dir, args.report)
        (args.report / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
        sys.stderr.write("report: " + ", ".join(str(path) for path in written) + "\n")
    interrupted = len(outcomes) < trials
    if interrupted:
        summary["interrupted_after_trials"] = len(outcomes)
    if args.replay is not None:
        summary["replay_repeats"] = REPLAY_REPEATS
    if args.json:
        sys.stdout.write(json.dumps(summary) + "\n")
    else:
        if interrupted:
            sys.stdout.write(f"interrupted: {len(outcomes)} of {trials} trial(s) done\n")
        sys.stdout.write(format_table(summary) + "\n\n" + format_targets(summary) + "\n")
        if args.replay is not None:
            sys.stdout.write(f"replayed: {REPLAY_REPEATS}\n")
    if interrupted:
        return INTERRUPTED_EXIT_CODE
    return 0 if summary["successes"] == summary["trials"] else 1


def write_recorded_pictures(record_dir: Path) -> None:
    """After `demo --record DIR`: the strip and GIF from the frames the sim node saved."""
    from sila_labware.benchmarks.campaign_report import write_run_pictures

    written = write_run_pictures(record_dir / "frames", record_dir)
    sys.stderr.write("pictures: " + ", ".join(str(path) for path in written) + "\n")
