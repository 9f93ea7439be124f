"""Whether a refactor kept the CPU cost of a transfer: two checkouts, the same seeds, interleaved.

    python -m sila_labware.benchmarks.interleaved_cpu --before DIR --after DIR
        [--seeds START COUNT] [--rounds N] [--random-layouts] [--python PATH] [--json]

The bound a refactor is held to: CPU seconds per trial within 10 % of before, measured in
interleaved runs of the same seeds on the same machine. Why CPU and not wall time: a campaign's
wall time follows the machine's load; its CPU time much less, but still some (caches, clock
frequency, other work on the same cores). So each round runs the same campaign in each checkout
back to back, and alternates which goes first, so that a drift in load falls on both alike.

Each run is `<python> -m sila_labware.cli bench --trials COUNT --seed START --jobs 1 --json` with
the checkout as working folder and first on PYTHONPATH: the checkout's own packages are imported,
the venv's (shared, identical) ROS interface package with them. Its CPU is that of the whole
process tree (`getrusage(RUSAGE_CHILDREN)` before and after). A descendant whose parent ends
without waiting for it (the campaign's robot-side fork server, about 1.3 s of CPU at 2818f60)
would be reaped by init and left out; this process is a child subreaper, so it adopts and reaps
them and counts their CPU too.

Exit codes: 0 within the bound and every trial delivered, 1 over it, a trial not delivered or a
campaign without a summary, 2 bad usage or a checkout that does not import its own packages.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import logging
import os
import resource
import statistics
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from sila_labware.deployment.prewarmed import PR_SET_CHILD_SUBREAPER

logger = logging.getLogger(__name__)

SIDES = ("before", "after")
BOUND = 0.10  # after/before of the medians may differ from 1 by this much
ORPHAN_WAIT_S = 30.0  # for descendants still running after the campaign's own process ended
NOT_PACKAGES = ("tests",)  # top-level folders with an __init__.py that the campaign does not import
# Where a package is found, without running its code (an import could fail for other reasons).
LOCATE = (
    "import importlib.util, json, sys\n"
    "specs = {name: importlib.util.find_spec(name) for name in sys.argv[1:]}\n"
    "print(json.dumps({name: spec and spec.origin for name, spec in specs.items()}))\n"
)


class CampaignError(RuntimeError):
    """A campaign run gave no summary to measure by (it did not start, crashed or was refused)."""


@dataclass(frozen=True)
class CampaignSummary:
    """What a run's `bench --json` says about its trials: enough to tell whether its CPU counts."""

    trials: int  # trials done (fewer than asked if interrupted)
    delivered: int
    failed: tuple[str, ...]  # "seed S: cause (error)" per trial that did not deliver


@dataclass(frozen=True)
class Run:
    """One campaign run in one checkout, with the CPU and wall time of its whole process tree."""

    side: str
    round: int
    cpu_s: float
    wall_s: float
    trials: int
    delivered: int
    failed: tuple[str, ...]
    exit_code: int

    @property
    def cpu_per_trial(self) -> float:
        return self.cpu_s / self.trials

    @property
    def wall_per_trial(self) -> float:
        return self.wall_s / self.trials


@dataclass(frozen=True)
class Comparison:
    """After against before: the medians of CPU s per trial, their ratio and the verdict."""

    before_median: float
    after_median: float
    ratio: float
    bound: float

    @property
    def within(self) -> bool:
        # Cheaper by more than the bound fails too: the refactor was to keep the cost, and a large
        # drop more often means work skipped than work saved.
        return round(abs(self.ratio - 1.0), 9) <= self.bound  # 11 / 10 - 1 is 0.10000000000000009

    @property
    def verdict(self) -> str:
        return f"{'within' if self.within else 'over'} {100 * self.bound:g} %"


def interleaved_order(rounds: int) -> list[tuple[int, str]]:
    """(round, side) in the order run: before first in even rounds, after first in odd ones, so
    that a slow drift of the machine's load weighs on both sides equally."""
    order = []
    for round_index in range(rounds):
        sides = SIDES if round_index % 2 == 0 else SIDES[::-1]
        order.extend((round_index, side) for side in sides)
    return order


def compare(before: Sequence[float], after: Sequence[float], bound: float = BOUND) -> Comparison:
    """Medians, not means: one run disturbed by the machine moves a median of three the least."""
    before_median = float(statistics.median(before))
    after_median = float(statistics.median(after))
    return Comparison(before_median, after_median, after_median / before_median, bound)


def parse_campaign(stdout: str) -> CampaignSummary:
    """The summary in `bench --json`'s stdout (its last JSON line); CampaignError if there is none,
    for example the object of a run refused or failed before its first trial."""
    lines = [line for line in stdout.splitlines() if line.startswith("{")]
    if not lines:
        raise CampaignError("no JSON object on stdout")
    summary = json.loads(lines[-1])
    if "trials" not in summary:
        raise CampaignError(summary.get("error") or "a JSON object without trials")
    failed = tuple(
        f"seed {trial['seed']}: {trial['cause']} ({trial['error']})" for trial in summary["failed_trials"]
    )
    return CampaignSummary(summary["trials"], summary["successes"], failed)


def checkout_problems(python: str, checkout: Path) -> list[str]:
    """Why runs in `checkout` would not measure its own code: a package that resolves elsewhere
    (another clone, the venv's editable install) or none. Empty if every top-level package of
    the checkout resolves into it, as the campaign runs them."""
    packages = sorted(
        path.parent.name for path in checkout.glob("*/__init__.py") if path.parent.name not in NOT_PACKAGES
    )
    if "sila_labware" not in packages:
        return [f"{checkout}: no sila_labware package: not a checkout of this repository"]
    located = subprocess.run(
        [python, "-c", LOCATE, *packages],
        cwd=checkout, env=checkout_environment(checkout), capture_output=True, text=True, check=False,
    )  # fmt: skip
    if located.returncode != 0:
        return [f"{checkout}: {python} could not locate its packages: {located.stderr.strip()[-500:]}"]
    problems = []
    for name, origin in json.loads(located.stdout).items():
        if origin is None:
            problems.append(f"{checkout}: {name} not found")
        elif not Path(origin).is_absolute() or not Path(origin).resolve().is_relative_to(checkout.resolve()):
            problems.append(f"{checkout}: {name} resolves to {origin}, outside the checkout")
    return problems


def checkout_environment(checkout: Path) -> dict[str, str]:
    """This process's environment with the checkout first on PYTHONPATH."""
    environment = dict(os.environ)
    paths = [str(checkout), *filter(None, environment.get("PYTHONPATH", "").split(os.pathsep))]
    environment["PYTHONPATH"] = os.pathsep.join(paths)
    return environment


def checkout_commit(checkout: Path) -> str:
    """The checkout's commit, `+changes` if its tracked files differ from it: the figure's source."""
    head = subprocess.run(
        ["git", "-C", str(checkout), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    )
    if head.returncode != 0:
        return "unknown"
    changed = subprocess.run(["git", "-C", str(checkout), "diff", "--quiet", "HEAD"], capture_output=True)
    return head.stdout.strip() + ("+changes" if changed.returncode else "")


def become_subreaper() -> None:
    """Adopt orphaned descendants (Linux), so their CPU reaches RUSAGE_CHILDREN when reaped here."""
    if ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_CHILD_SUBREAPER) failed")


def reap_orphans(timeout_s: float = ORPHAN_WAIT_S) -> list[int]:
    """Wait for every adopted descendant to end and reap it; the pids still running at the
    deadline (their CPU then falls into whichever later run reaps them)."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            pid, _status = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return []
        if pid:
            continue
        if time.monotonic() >= deadline:
            return _children()
        time.sleep(0.05)


def _children() -> list[int]:
    children = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()  # after the command name
        except (OSError, IndexError):
            continue
        if int(fields[1]) == os.getpid():
            children.append(int(stat.parent.name))
    return children


def children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def measure(
    command: Sequence[str], cwd: Path, environment: dict[str, str]
) -> tuple[subprocess.CompletedProcess[str], float, float]:
    """Run `command` to its end: its result, the CPU s of its whole process tree (orphans reaped
    by this process included) and its wall s."""
    cpu_before = children_cpu_s()
    started = time.monotonic()
    done = subprocess.run(command, cwd=cwd, env=environment, capture_output=True, text=True, check=False)
    wall_s = time.monotonic() - started
    lingering = reap_orphans()
    if lingering:
        logger.warning("still running %.0f s after %s ended: %s", ORPHAN_WAIT_S, command[:3], lingering)
    return done, children_cpu_s() - cpu_before, wall_s


def bench_command(python: str, first_seed: int, trials: int, random_layouts: bool) -> list[str]:
    command = [python, "-m", "sila_labware.cli", "bench", "--trials", str(trials), "--seed", str(first_seed)]
    return [*command, "--jobs", "1", "--json", *(["--random-layouts"] if random_layouts else [])]


def run_interleaved(checkouts: dict[str, Path], command: list[str], trials: int, rounds: int) -> list[Run]:
    """Every run of every round in interleaved order; CampaignError on a run without a summary."""
    runs = []
    for round_index, side in interleaved_order(rounds):
        logger.info("round %d, %s: %s", round_index + 1, side, checkouts[side])
        checkout = checkouts[side]
        done, cpu_s, wall_s = measure(command, checkout, checkout_environment(checkout))
        try:
            summary = parse_campaign(done.stdout)
        except (CampaignError, ValueError) as error:
            tail = "\n".join(done.stderr.strip().splitlines()[-5:])
            raise CampaignError(
                f"{side} ({checkout}), round {round_index + 1}: exit {done.returncode}, {error}\n{tail}"
            ) from error
        if summary.trials == 0:
            raise CampaignError(f"{side} ({checkout}), round {round_index + 1}: no trial done")
        run = Run(side, round_index, cpu_s, wall_s, summary.trials, summary.delivered, summary.failed,
                  done.returncode)  # fmt: skip
        logger.info("%.2f CPU s, %.2f wall s per trial", run.cpu_per_trial, run.wall_per_trial)
        runs.append(run)
    return runs


def undelivered(runs: Sequence[Run], asked: int) -> list[str]:
    """One line per run that did not deliver every trial asked for (a failed trial stops early
    and an interrupted campaign ran fewer: either changes the CPU per trial)."""
    return [
        f"{run.side} round {run.round + 1}: {run.delivered} of {asked} delivered"
        + "".join(f"; {failed}" for failed in run.failed)
        for run in runs
        if run.delivered < asked
    ]


def report(
    runs: Sequence[Run], checkouts: dict[str, Path], args: argparse.Namespace
) -> tuple[dict[str, Any], int]:
    """The figures as one JSON-ready object, and the exit code."""
    first_seed, trials = args.seeds
    sides = {}
    for side in SIDES:
        cpu = [run.cpu_per_trial for run in runs if run.side == side]
        wall = [run.wall_per_trial for run in runs if run.side == side]
        sides[side] = {
            "checkout": str(checkouts[side]),
            "commit": checkout_commit(checkouts[side]),
            "cpu_s_per_trial": cpu,
            "cpu_s_per_trial_median": statistics.median(cpu),
            "wall_s_per_trial": wall,
            "wall_s_per_trial_median": statistics.median(wall),
        }
    cpu = compare(*(sides[side]["cpu_s_per_trial"] for side in SIDES))
    wall = compare(*(sides[side]["wall_s_per_trial"] for side in SIDES))
    missing = undelivered(runs, trials)
    figures = {
        "seeds": {"start": first_seed, "count": trials},
        "rounds": args.rounds,
        "random_layouts": args.random_layouts,
        "python": args.python,
        **sides,
        "cpu_ratio_after_before": cpu.ratio,
        "wall_ratio_after_before": wall.ratio,
        "bound": cpu.bound,
        "verdict": cpu.verdict,
        "undelivered": missing,
        "runs": [asdict(run) for run in runs],
    }
    return figures, 0 if cpu.within and not missing else 1


def format_report(figures: dict[str, Any]) -> str:
    """The figures as lines for a person: runs, medians, ratios and the verdict."""
    seeds = figures["seeds"]
    lab = "random layouts" if figures["random_layouts"] else "default lab"
    lines = [
        f"seeds {seeds['start']}..{seeds['start'] + seeds['count'] - 1} ({seeds['count']} trial(s) per "
        f"run), {figures['rounds']} round(s), {lab}, {figures['python']}"
    ]
    for side in SIDES:
        figure = figures[side]
        lines += [
            f"{side:6} {figure['checkout']} ({figure['commit']})",
            f"  CPU s per trial:  {_numbers(figure['cpu_s_per_trial'])}  median "
            f"{figure['cpu_s_per_trial_median']:.2f}",
            f"  wall s per trial: {_numbers(figure['wall_s_per_trial'])}  median "
            f"{figure['wall_s_per_trial_median']:.2f}",
        ]
    cpu, wall = figures["cpu_ratio_after_before"], figures["wall_ratio_after_before"]
    lines.append(
        f"after/before of the medians: CPU {cpu:.3f} ({100 * (cpu - 1):+.1f} %), "
        f"wall {wall:.3f} ({100 * (wall - 1):+.1f} %)"
    )
    for missing in figures["undelivered"]:
        lines.append(f"not all delivered: {missing}")
    doubt = " (doubtful: not every trial delivered, and a failed trial changes the CPU)"
    lines.append(f"verdict: {figures['verdict']}{doubt if figures['undelivered'] else ''}")
    return "\n".join(lines)


def _numbers(values: Sequence[float]) -> str:
    return " ".join(f"{value:.2f}" for value in values)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m sila_labware.benchmarks.interleaved_cpu",
        description="CPU s per trial of the same campaign in two checkouts, runs interleaved.",
    )
    parser.add_argument("--before", type=Path, required=True, metavar="DIR", help="checkout before")
    parser.add_argument("--after", type=Path, required=True, metavar="DIR", help="checkout after")
    parser.add_argument(
        "--seeds", type=int, nargs=2, default=[900000, 6], metavar=("START", "COUNT"),
        help="the trial seeds of every run (default: %(default)s)",
    )  # fmt: skip
    parser.add_argument("--rounds", type=int, default=3, help="runs per checkout (default: %(default)s)")
    parser.add_argument("--random-layouts", action="store_true", help="passed on to bench")
    parser.add_argument("--python", default=sys.executable, help="interpreter (default: this one)")
    parser.add_argument("--json", action="store_true", help="one JSON object on stdout")
    args = parser.parse_args(argv)
    if args.seeds[1] < 1 or args.rounds < 1:
        parser.error("--seeds COUNT and --rounds need at least one")
    logging.basicConfig(level=logging.INFO, format="interleaved_cpu: %(message)s")
    checkouts = {"before": args.before.resolve(), "after": args.after.resolve()}
    problems = [problem for side in SIDES for problem in checkout_problems(args.python, checkouts[side])]
    if problems:
        sys.stderr.write("refusing to measure:\n  " + "\n  ".join(problems) + "\n")
        return 2
    if checkouts["before"] == checkouts["after"]:
        logger.warning("before and after are the same checkout: this measures the noise only")
    become_subreaper()
    command = bench_command(args.python, args.seeds[0], args.seeds[1], args.random_layouts)
    try:
        runs = run_interleaved(checkouts, command, args.seeds[1], args.rounds)
    except CampaignError as error:
        sys.stderr.write(f"interleaved_cpu: {error}\n")
        if args.json:
            print(json.dumps({"success": False, "error": str(error).splitlines()[0]}))
        return 1
    figures, exit_code = report(runs, checkouts, args)
    print(json.dumps({**figures, "success": exit_code == 0}) if args.json else format_report(figures))
    return exit_code


if __name__ == "__main__":
    sys.exit(main())
