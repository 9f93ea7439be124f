"""One transfer at a set pace, through the Python SiLA client: is a paced robot's timing honest?

    python -m sila_labware.benchmarks.paced_transfer [--pace 1.0] [--world FILE] [--json] [--log-dir DIR]
        [--port-base P]   (runs side by side need their own port bases)

Why: at `--pace 1` a client should see a real robot's timing. Two figures say whether it does:
- the transfer's wall time against its simulated time (the robot's /robot_state clock): their
  ratio should be the pace, idle time between the steps included;
- the remaining time the robot server reports for GetLabware and PutLabware when the command is
  about half done, against what really remained (the wall time from that report to the step's
  end): SiLA remaining times are wall seconds, converted by the bridge at the robot's pace.

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

from sila_labware.client import StepProgress
from sila_labware.client.sequence import GET_LABWARE, PUT_LABWARE
from sila_labware.deployment.clients import transfer_client
from sila_labware.deployment.stack import Deployment, DeploymentOptions

logger = logging.getLogger(__name__)

DEFAULT_WORLD = Path(__file__).resolve().parents[2] / "lab_description" / "worlds" / "default.yaml"
WATCHED_STEPS = (GET_LABWARE, PUT_LABWARE)
HALFWAY = 0.5


@dataclass
class RemainingAtHalfway:
    """One watched step: what the server said remained near half way, and what did."""

    step: str
    progress: float
    reported_s: float | None
    real_s: float

    @property
    def error_fraction(self) -> float | None:
        if self.reported_s is None or self.real_s <= 0:
            return None
        return (self.reported_s - self.real_s) / self.real_s


@dataclass
class PacedTransferReport:
    pace: float
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0
    remaining: list[RemainingAtHalfway] = field(default_factory=list)

    @property
    def sim_per_wall(self) -> float:
        return self.sim_seconds / self.wall_seconds if self.wall_seconds > 0 else 0.0

    def as_json_object(self) -> dict[str, Any]:
        return {
            **asdict(self),
            "sim_per_wall": self.sim_per_wall,
            "remaining": [{**asdict(r), "error_fraction": r.error_fraction} for r in self.remaining],
        }


class ProgressSamples:
    """An `on_progress` callback keeping every record of the watched steps with its wall time."""

    def __init__(self) -> None:
        self.records: dict[str, list[tuple[float, StepProgress]]] = {step: [] for step in WATCHED_STEPS}

    def __call__(self, record: StepProgress) -> None:
        if record.step in self.records:
            self.records[record.step].append((time.monotonic(), record))

    def at_halfway(self, step: str) -> RemainingAtHalfway | None:
        """The running record nearest half way that carries an estimate, against the step's end."""
        records = self.records[step]
        ends = [wall for wall, record in records if record.done]
        estimates = [(w, r) for w, r in records if not r.done and r.remaining_s is not None]
        if not ends or not estimates:
            return None
        wall, record = min(estimates, key=lambda sample: abs(sample[1].progress - HALFWAY))
        return RemainingAtHalfway(step, record.progress, record.remaining_s, ends[0] - wall)


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
        samples = ProgressSamples()
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
        report.remaining = [m for step in WATCHED_STEPS if (m := samples.at_halfway(step)) is not None]
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
    for sample in report.remaining:
        reported = "none" if sample.reported_s is None else f"{sample.reported_s:.1f} s"
        sys.stdout.write(
            f"{sample.step} at {100 * sample.progress:.0f} %: remaining reported {reported}, "
            f"real {sample.real_s:.1f} s\n"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
