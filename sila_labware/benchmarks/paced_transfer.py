"""One transfer at a set pace, through the Python SiLA client: is a paced robot's timing honest?

    python -m sila_labware.benchmarks.paced_transfer [--pace 1.0] [--world FILE] [--json] [--log-dir DIR]
        [--port-base P]   (runs side by side need their own port bases)

Why: at `--pace 1` a client should see a real robot's timing. Two figures say whether it does:
- the transfer's wall time against its simulated time (the robot's /robot_state clock): their
  ratio should be the pace, idle time between the steps included;
- the remaining time the servers report for each step at each quarter of its duration, against
  what really remained (sila_labware.client.remaining_time): SiLA remaining times are wall
  seconds, converted by the bridge at the robot's pace.

A benchmark, not a test: the figures depend on the machine's load. Prints one JSON object with
`--json`, else a few lines.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from sila_labware.client.remaining_time import TOLERANCE, RemainingCheck, RemainingSampler, share_within
from sila_labware.deployment.clients import transfer_client
from sila_labware.deployment.stack import Deployment, DeploymentOptions

logger = logging.getLogger(__name__)

DEFAULT_WORLD = Path(__file__).resolve().parents[2] / "lab_description" / "worlds" / "default.yaml"


@dataclass
class PacedTransferReport:
    pace: float
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0
    remaining: list[RemainingCheck] = field(default_factory=list)

    @property
    def sim_per_wall(self) -> float:
        return self.sim_seconds / self.wall_seconds if self.wall_seconds > 0 else 0.0

    def as_json_object(self) -> dict[str, Any]:
        return {
            **asdict(self),
            "sim_per_wall": self.sim_per_wall,
            "remaining_share_within": share_within(self.remaining),
        }


def run(
    world: Path, pace: float, scratch: Path, log_dir: Path | None = None, port_base: int | None = None
) -> PacedTransferReport:
    """Start a deployment at `pace`, move the first station's plate to the second, measure."""
    options = DeploymentOptions(
        world=world, port_base=0, ca_file=scratch / "ca.pem", discovery=False, pace=pace, log_dir=log_dir
    )
    options.port_base = _free_port_base() if port_base is None else port_base
    deployment = Deployment(options)
    deployment.start()
    try:
        assert deployment.link is not None and deployment.workcell is not None
        link = deployment.link
        source, destination = deployment.workcell.stations[:2]
        nests = link.nest_readings()
        plate = next(n for n in nests if n.nest.station == source.name and n.occupied)
        free = next(n for n in nests if n.nest.station == destination.name and not n.occupied)
        samples = RemainingSampler()
        report = PacedTransferReport(pace)
        wall_start, sim_start = time.monotonic(), link.robot_status().stamp_s
        with transfer_client(deployment) as client:
            client.transfer(
                (source.name, plate.nest.sub_position),
                (destination.name, free.nest.sub_position),
                labware_id=plate.labware_id,
                on_progress=samples,
            )
        report.wall_seconds = time.monotonic() - wall_start
        report.sim_seconds = link.robot_status().stamp_s - sim_start
        report.remaining = samples.checks
        return report
    finally:
        deployment.stop()


def _free_port_base() -> int:
    from sila_labware.servers.serving import port_is_free

    for base in range(51800, 60000, 8):
        if all(port_is_free("127.0.0.1", port) for port in range(base, base + 4)):
            return base
    raise RuntimeError("no four free ports from 51800 on")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m sila_labware.benchmarks.paced_transfer")
    parser.add_argument("--pace", type=float, default=1.0, help="times real time (default: %(default)s)")
    parser.add_argument("--world", type=Path, default=DEFAULT_WORLD)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--log-dir", type=Path, default=None, help="keep the robot side's logs here")
    parser.add_argument(
        "--port-base", type=int, default=None, help="SiLA ports from here (default: the first four free)"
    )
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    with tempfile.TemporaryDirectory(prefix="sila-labware-paced-") as scratch:
        report = run(args.world, args.pace, Path(scratch), args.log_dir, args.port_base)
    if args.json:
        sys.stdout.write(json.dumps(report.as_json_object()) + "\n")
        return 0
    sys.stdout.write(
        f"pace {report.pace:g}: {report.sim_seconds:.1f} s simulated in {report.wall_seconds:.1f} s wall "
        f"(ratio {report.sim_per_wall:.3f})\n"
    )
    for check in (check for check in report.remaining if check.judged):
        errors = ", ".join("no estimate" if e is None else f"{100 * e:+.0f} %" for e in check.errors)
        verdict = "within" if check.within else "OUTSIDE"
        sys.stdout.write(
            f"{check.step} ({check.duration_s:.1f} s): remaining time at its quarters off by {errors} "
            f"of the step ({verdict} {100 * TOLERANCE:.0f} %)\n"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
