"""How many labs drawn from lab furniture as it is sold does `world check` accept, and why not the rest.

Why: a lab integrator describes their own lab; the robot must serve ordinary furniture, not labs
drawn to suit it. Each seed draws a floor plan from `station_draw.RANGES` with no robot field in
it (the floor-plan rules only: benches inside the floor, clear of each other and of the drives),
and it is then checked as `world check` does: the loader with the robot model, and the planner's
ways between the POIs and out of every pose the robot works at. A refused lab lists
each reason; `reason_kind` sorts them for the table.

    python -m tiago_sim.layouts.acceptance FIRST COUNT
"""

from __future__ import annotations

import argparse
import random
import re
import sys
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

from lab_description.world import WorldError, world_from_raw
from tiago_sim.inspection.poi_paths import plan_poi_paths
from tiago_sim.inspection.reach_sweep import NestReach, sweep_world, unserved
from tiago_sim.layouts.generator import draw_floor_plan


@dataclass(frozen=True)
class Verdict:
    """One drawn lab: accepted, or the loader's reasons for refusing it (one line each)."""

    seed: int
    raw: dict
    problems: tuple[str, ...]

    @property
    def accepted(self) -> bool:
        return not self.problems


def check_seed(seed: int) -> Verdict:
    """The first floor plan drawn for `seed`, checked with the robot model."""
    return check_lab(seed, draw_floor_plan(random.Random(seed), seed))


def check_lab(seed: int, raw: dict) -> Verdict:
    """A drawn lab checked as `world check` does: the loader, then the robot's ways between the POIs
    and out of every pose it works at (`poi_paths`)."""
    source = f"furniture lab {seed}"
    try:
        world = world_from_raw(raw, source)
    except WorldError as error:
        return Verdict(seed, raw, error.problems)
    return Verdict(seed, raw, tuple(plan_poi_paths(world).problems(source)))


@dataclass(frozen=True)
class Confirmation:
    """A refused lab against the reach sweep: the nests no pose serves for the lab's tallest labware
    type (the refusal is confirmed when there is one), and those that serve no type at all."""

    tallest: tuple[NestReach, ...]
    any_type: tuple[NestReach, ...]

    @property
    def confirmed(self) -> bool:
        return bool(self.tallest)


def confirm(verdict: Verdict) -> Confirmation:
    """Sweep a refused lab's nests (`reach_sweep`) with its floor plan alone."""
    world = world_from_raw(verdict.raw, f"furniture lab {verdict.seed}", check_robot=False)
    tallest = max(world.labware_types, key=lambda name: world.labware_types[name].height)
    reaches = sweep_world(world)
    every_type = list(world.labware_types)
    return Confirmation(tuple(unserved(reaches, [tallest])), tuple(unserved(reaches, every_type)))


def reason_kind(problem: str) -> str:
    """A refusal's kind: reach, view, base (footprint or turning room), the robot's ways, or other."""
    if re.search(r"no path for the robot|could not leave", problem):
        return "no way for the robot"  # first: the planner's reasons say "reaches"
    if "reach" in problem:
        return "a nest out of reach"
    if "cannot see marker" in problem:
        return "a marker out of view"
    if re.search(r"m from bench|the undock drive|m from the dock", problem):
        return "no room for the base"
    return "other"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m tiago_sim.layouts.acceptance", description=__doc__.split("\n")[0]
    )
    parser.add_argument("first", type=int)
    parser.add_argument("count", type=int)
    args = parser.parse_args(argv)
    kinds: Counter[str] = Counter()
    unconfirmed: Counter[str] = Counter()
    accepted = confirmed = any_type = 0
    for seed in range(args.first, args.first + args.count):
        verdict = check_seed(seed)
        accepted += verdict.accepted
        reasons = {reason_kind(problem) for problem in verdict.problems}
        kinds.update(reasons)
        if verdict.accepted:
            continue
        sys.stdout.write(f"{seed}: refused: {verdict.problems[0]}\n")
        sweep = confirm(verdict)
        confirmed += sweep.confirmed
        any_type += bool(sweep.any_type)
        if sweep.confirmed:
            sys.stdout.write(f"  confirmed by the reach sweep: {sweep.tallest[0].line()}\n")
        else:
            unconfirmed.update(reasons)
            sys.stdout.write("  not confirmed: the reach sweep serves every nest from some pose\n")
    refused = args.count - accepted
    sys.stdout.write(f"accepted {accepted} of {args.count} labs ({100.0 * accepted / args.count:.1f} %)\n")
    for kind, count in kinds.most_common():
        sys.stdout.write(f"  refused for {kind}: {count}\n")
    sys.stdout.write(
        f"refusals confirmed by the reach sweep: {confirmed} of {refused} (a nest no base pose serves with "
        f"the tallest labware type; {any_type} with no type at all)\n"
    )
    for kind, count in unconfirmed.most_common():
        sys.stdout.write(f"  not confirmed, refused for {kind}: {count}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
