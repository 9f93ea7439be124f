"""`python -m tiago_sim.layouts SEED [SEED ...] (--out DIR | --file FILE) [--furnish WORLD]`: write
random layouts, or with `--furnish` the world WORLD with random obstacles per seed (`furnish`).

Why a command: the SiLA side (`sila-labware bench --random-layouts`, `--save-layout`) does not
import the simulation's packages; it runs this module as a child process, once per campaign.
Each layout is written as `DIR/layout_SEED.yaml` (or to FILE for a single seed), a world file
`demo --world` runs. Exit codes: 0 written, 1 a seed had no valid layout, 2 bad usage.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from lab_description.world import WorldError
from tiago_sim.layouts.generator import LayoutError
from tiago_sim.layouts.layout_file import write_layout


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tiago_sim.layouts", description=__doc__.split("\n")[0])
    parser.add_argument("seeds", type=int, nargs="+", metavar="SEED")
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--out", type=Path, metavar="DIR", help="write DIR/layout_SEED.yaml per seed")
    where.add_argument("--file", type=Path, metavar="FILE", help="write the one seed's layout here")
    parser.add_argument(
        "--furnish",
        type=Path,
        metavar="WORLD",
        help="not a random lab: WORLD with 1 to 3 random obstacles per seed",
    )
    args = parser.parse_args(argv)
    if args.file is not None and len(args.seeds) != 1:
        parser.error("--file takes exactly one seed")
    try:
        for seed in args.seeds:
            path = args.file if args.file is not None else args.out / f"layout_{seed}.yaml"
            write_layout(seed, path, args.furnish)
            sys.stdout.write(f"{path}\n")
    except (LayoutError, WorldError) as error:
        sys.stderr.write(f"{error}\n")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
