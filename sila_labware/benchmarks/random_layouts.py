"""`bench --random-layouts`, `bench --random-obstacles` and `bench --save-layout SEED FILE`: a new
lab per trial, from its seed (a random lab, or the campaign's world with random obstacles).

Why child processes: the layouts are drawn and checked on the robot side (`tiago_sim.layouts`,
the loader's robot checks need the robot model), which the SiLA side does not import; as for
`world check`, it runs that module. All of a campaign's layouts are drawn before the first trial,
in as many children as the campaign has workers (about 0.2 s a layout). A failed trial's layout is
copied next to the report, as `layout_SEED.yaml`, so that `demo --world` runs it.
Threads: the caller's (the CLI's main thread).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

from sila_labware.benchmarks.campaign import TrialOutcome

LAYOUT_MODULE = "tiago_sim.layouts"
SECONDS_PER_LAYOUT = 10.0  # timeout budget; a layout takes about 0.2 s, a few up to 3 s


class LayoutGenerationError(RuntimeError):
    """The layout generator failed (its message is the child's error output)."""


def generate_layouts(
    seeds: Sequence[int], directory: Path, jobs: int = 1, furnish: Path | None = None
) -> None:
    """Write `directory/layout_SEED.yaml` for every seed, in up to `jobs` children at once; with
    `furnish`, that world with the seed's random obstacles instead of a random lab."""
    directory.mkdir(parents=True, exist_ok=True)
    chunks = [list(seeds[index::jobs]) for index in range(max(1, jobs))]
    children = [
        subprocess.Popen(
            [
                sys.executable,
                "-m",
                LAYOUT_MODULE,
                *map(str, chunk),
                "--out",
                str(directory),
                *_furnish(furnish),
            ],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )  # fmt: skip
        for chunk in chunks
        if chunk
    ]
    errors = []
    for child in children:
        _, stderr = child.communicate(timeout=60.0 + SECONDS_PER_LAYOUT * len(seeds))
        if child.returncode != 0:
            errors.append(stderr.strip() or f"{LAYOUT_MODULE} exited with {child.returncode}")
    if errors:
        raise LayoutGenerationError("\n".join(errors))


def _furnish(world: Path | None) -> list[str]:
    return [] if world is None else ["--furnish", str(world)]


def save_layout(seed: int, target: Path, furnish: Path | None = None) -> None:
    """Write the random layout `seed` to `target` (the file a --random-layouts trial with that seed
    runs; with `furnish`, the world a --random-obstacles trial runs)."""
    done = subprocess.run(
        [sys.executable, "-m", LAYOUT_MODULE, str(seed), "--file", str(target), *_furnish(furnish)],
        stdin=subprocess.DEVNULL, capture_output=True, text=True, check=False,
        timeout=60.0 + SECONDS_PER_LAYOUT,
    )  # fmt: skip
    if done.returncode != 0:
        raise LayoutGenerationError(done.stderr.strip() or f"{LAYOUT_MODULE} exited with {done.returncode}")


def keep_failed_layouts(outcomes: Sequence[TrialOutcome], report_dir: Path) -> list[Path]:
    """Copy each failed trial's world file into the report directory, and point the trial's `world`
    at the copy (the originals are temporary); the copies."""
    kept = []
    for outcome in outcomes:
        if outcome.success or not outcome.world or not Path(outcome.world).is_file():
            continue
        target = report_dir / f"layout_{outcome.seed}.yaml"
        shutil.copyfile(outcome.world, target)
        outcome.world = str(target)
        kept.append(target)
    return kept
