"""The `estimates_s` rows of sequencer.yaml from sequencer logs: the median robot seconds per step kind.

    python -m tiago_sim.sequencer.step_table LOG [LOG ...]

Why a tool: the table is measured, and the code it measures changes; re-measuring must be a
command, not arithmetic by hand. Each log is a sequencer's (`--log-dir` of the paced benchmark),
whose "KIND took S s (estimated E s)" lines say what every step of a task took. Prints one YAML
line per kind of the two tasks, in plan order, ready to replace the kind rows of `estimates_s`.
The median, not the mean: a few labs' hard geometry (an approach of 4.8 s where most take 0.9 s)
made the means long for the typical lab, and GetLabware's remaining time 9 to 12 % long at its
first quarter in the default lab.
"""

from __future__ import annotations

import re
import statistics
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path

from tiago_sim.sequencer.step_durations import KIND_SEPARATOR_IN_PARAMETERS

# the arm and gripper steps of a task; a drive's or undock's duration depends on the lab (the table's
# action rows hold those)
TOOK = re.compile(
    r"((?:GetLabware|PutLabware):(?:marker_motion|play_motion|gripper):\S+) took (\d+(?:\.\d+)?) s"
)


def durations_by_kind(lines: Iterable[str]) -> dict[str, list[float]]:
    """Every task step's duration, per kind, in the order the kinds first appear."""
    kinds: dict[str, list[float]] = {}
    for line in lines:
        match = TOOK.search(line)
        if match:
            kinds.setdefault(match.group(1), []).append(float(match.group(2)))
    return kinds


def table_rows(kinds: dict[str, list[float]]) -> list[str]:
    """`estimates_s` lines: the kind as a parameter name and its median, to a hundredth of a second."""
    return [
        f"  {kind.replace(':', KIND_SEPARATOR_IN_PARAMETERS)}: {statistics.median(values):.2f}"
        f"  # n={len(values)}, {min(values):.2f}..{max(values):.2f}"
        for kind, values in kinds.items()
    ]


def main(argv: Sequence[str] | None = None) -> int:
    paths = [Path(arg) for arg in (sys.argv[1:] if argv is None else argv)]
    if not paths:
        sys.stderr.write("usage: python -m tiago_sim.sequencer.step_table LOG [LOG ...]\n")
        return 2
    kinds = durations_by_kind(line for path in paths for line in path.read_text().splitlines())
    sys.stdout.write("\n".join(table_rows(kinds)) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
