"""Start the task sequencer node: its parameters (sequencer.yaml) and its command line.

python -m tiago_sim.sequencer [--world FILE] [--params FILE] [--inventory FILE] [--label-checks]
"""

from __future__ import annotations

import argparse
import logging
from pathlib import Path
from typing import Any

import yaml
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from tiago_sim.node_main import spin_node, stacks_on_sigusr1
from tiago_sim.sequencer.node import PARAMETERS, Sequencer, log

DEFAULT_PARAMS = Path(__file__).with_name("sequencer.yaml")
DESCRIPTION = "Task sequencer: GetLabware and PutLabware as sequences of the robot's own actions."


def load_params(path: Path) -> dict[str, Any]:
    params = yaml.safe_load(Path(path).read_text())
    missing = {*PARAMETERS, "estimates_s"} - set(params)
    if missing:
        raise ValueError(f"{path}: missing {', '.join(sorted(missing))}")
    return params


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m tiago_sim.sequencer",
        description=DESCRIPTION,
    )
    parser.add_argument(
        "--world", type=Path, default=None, help="accepted for symmetry; the robot describes the cell"
    )
    parser.add_argument(
        "--params", type=Path, default=DEFAULT_PARAMS, help="parameter YAML (default: %(default)s)"
    )
    parser.add_argument(
        "--inventory",
        type=Path,
        default=None,
        help="file that keeps the labware inventory across restarts (default: kept in memory only)",
    )
    parser.add_argument(
        "--label-checks",
        action="store_true",
        help="refuse a transfer whose plate's label reads other than the goal's labware id",
    )
    parser.add_argument("--log-level", default="INFO")
    args = parser.parse_args(argv)
    stacks_on_sigusr1()
    logging.basicConfig(level=args.log_level, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    params = load_params(args.params)
    params["label_checks"] = bool(params["label_checks"]) or args.label_checks

    def build(node: Node) -> Sequencer:
        sequencer = Sequencer(node, params, args.inventory)
        log.info("sequencer ready")
        return sequencer

    return spin_node("labware_sequencer", SingleThreadedExecutor, build)
