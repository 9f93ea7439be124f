"""Command line entry point `sila-labware`: serve the robot and its stations over SiLA, or run the demo.

    sila-labware serve --world FILE [--host H] [--port-base N] [--insecure] [--ca-file PATH] [--pace X]
        [--ros-adapter]
                       [--print-config json]   (connection details as JSON: deployment/connection_config)
    sila-labware demo  --world FILE [--json] [--record DIR] [--pace X] [stack options as serve]
    sila-labware bench --trials N --seed S [--json] [--report DIR] [--replay SEED] [levels] (bench_cli)
    sila-labware bluesky-demo --world FILE   (the same robot driven from a Bluesky RunEngine plan)
    sila-labware world check FILE [--png OUT]   (validate a world file, draw it; deployment/world_file)

Exit codes: 0 success, 1 the demo transfer failed or the stack could not start (`world check`: the
file is invalid), 2 bad usage (an invalid world file included: every command with --world checks it
first), 130 `demo` or `bench` stopped by Ctrl-C or SIGTERM.

Machine-readable output: with `--json` (or `serve --print-config json`) stdout carries exactly one
JSON object whatever happens, usage errors included, with `success`, `error`, `error_kind` and
`exit_code` (deployment/json_outcome); the one-line reason is on stderr as without it.

Stopping and clean-up: Ctrl-C (or SIGTERM) stops `serve`, `demo` and `bench` at any point, start-up
included, within 5 s: the running transfer is abandoned (the robot is told to stop), the SiLA
servers, the bridge and the robot side's processes (in their own sessions, so a terminal's Ctrl-C
never reaches them) are stopped, and a second Ctrl-C does not cut that short. What a run creates
in the temp folder (the `sila-labware-demo-*` / `sila-labware-bench-*` directory holding the run's
CA file) is removed on success, failure and Ctrl-C.
"""

from __future__ import annotations

import argparse
import logging
import signal
import sys
import tempfile
import threading
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING

from sila_labware.benchmarks.campaign_cli import (
    INTERRUPTED_EXIT_CODE,
    add_bench_arguments,
    bench_command,
    validate_bench,
    write_recorded_pictures,
)
from sila_labware.deployment import json_outcome, pacing
from sila_labware.deployment.cli_arguments import (
    add_inventory_arguments,
    add_robot_side_arguments,
    add_stack_arguments,
)
from sila_labware.deployment.connection_config import add_print_config_argument, print_servers, write_config
from sila_labware.deployment.json_outcome import JsonOutput, UsageError, outcome_fields
from sila_labware.deployment.robot_limits_file import robot_limits_problem, use_robot_limits
from sila_labware.deployment.world_file import add_world_command, world_command, world_problems
from sila_labware.servers.refusal_log import install_refusal_log_filter

if TYPE_CHECKING:
    from sila_labware.deployment.demo import DemoReport
    from sila_labware.deployment.stack import Deployment, DeploymentOptions

logger = logging.getLogger("sila_labware")

DEFAULT_WORLD = Path(__file__).resolve().parents[1] / "lab_description" / "worlds" / "default.yaml"


class _Parser(argparse.ArgumentParser):
    """argparse, but usage errors are one line, `sila-labware: error: <reason>`, and raise
    UsageError (exit 2) so that `main` can add the JSON object a `--json` run promises."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        raise UsageError(message)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="sila-labware", description="A TIAGo++ mobile manipulator as a SiLA 2 labware-transfer device."
    )
    subcommands = parser.add_subparsers(
        dest="command", required=True, metavar="{serve,demo,bluesky-demo,bench,world}", parser_class=_Parser
    )

    serve = subcommands.add_parser(
        "serve", help="run the simulated robot and serve it and its stations over SiLA"
    )
    add_stack_arguments(serve, DEFAULT_WORLD)
    pacing.add_robot_arguments(serve)
    add_inventory_arguments(serve)
    add_print_config_argument(serve)
    demo = subcommands.add_parser(
        "demo", help="serve, then move the plate from the first station to the second"
    )
    add_stack_arguments(demo, DEFAULT_WORLD)
    pacing.add_robot_arguments(demo)
    demo.add_argument(
        "--json", action="store_true", help="print one JSON object with the outcome and timings"
    )
    demo.add_argument(
        "--record", type=Path, default=None, metavar="DIR", help="write pictures of the run here"
    )
    bench = subcommands.add_parser("bench", help="repeat the demo transfer under seeded disturbances")
    add_stack_arguments(bench, DEFAULT_WORLD)
    add_bench_arguments(bench)
    pacing.add_pace_argument(bench)
    bluesky = subcommands.add_parser(
        "bluesky-demo",
        help="run the robot side and a Bluesky plan: pickup, place, measure, return the plate",
    )
    add_robot_side_arguments(bluesky, DEFAULT_WORLD)
    add_world_command(subcommands, _Parser)
    return parser


def _validate(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    if args.command == "world":
        return
    if not args.world.is_file():
        parser.error(f"world file not found: {args.world}")
    if not 1 <= args.port_base <= 65535 - 16:
        parser.error(f"--port-base {args.port_base} is not a usable port")
    if args.name:
        from sila_labware.deployment.lab_name import check_lab_name

        try:
            check_lab_name(args.name)
        except ValueError as error:
            parser.error(f"--name: {error}")
    if args.domain_id is not None and not 0 <= args.domain_id <= 232:
        parser.error(f"--domain-id {args.domain_id} is outside 0..232")
    if problem := pacing.pace_problem(getattr(args, "pace", None), getattr(args, "ros_adapter", False)):
        parser.error(problem)
    if args.command == "bench":
        validate_bench(parser, args)
    if args.robot_limits is not None:
        if problem := robot_limits_problem(args.robot_limits):
            parser.error(f"--robot-limits: {problem}")
        use_robot_limits(args.robot_limits)
    problems = world_problems(args.world)  # last: a child process, the slowest check
    if problems:
        parser.error("invalid world file: " + "\n".join(problems))


class _StopRequest:
    """SIGINT/SIGTERM set a flag (and interrupt waits) instead of killing the process mid-way."""

    def __init__(self) -> None:
        self.event = threading.Event()

    def install(self) -> None:
        signal.signal(signal.SIGINT, self._handle)
        signal.signal(signal.SIGTERM, self._handle)

    def _handle(self, signum: int, _frame: FrameType | None) -> None:
        logger.info("signal %d: stopping", signum)
        self.event.set()


def _deployment_options(args: argparse.Namespace, ca_file: Path) -> DeploymentOptions:
    from sila_labware.deployment.stack import DeploymentOptions

    record = getattr(args, "record", None)
    if args.insecure:
        logger.warning(
            "serving WITHOUT encryption (--insecure): for tests only, the SiLA standard forbids it"
        )
    return DeploymentOptions(
        world=args.world,
        host=args.host,
        port_base=args.port_base,
        insecure=args.insecure,
        ca_file=ca_file,
        discovery=not args.no_discovery,
        domain_id=args.domain_id,
        ready_timeout_s=args.ready_timeout,
        log_dir=args.log_dir,
        extra_sim_arguments=[
            *([] if record is None else ["--record-dir", str(record / "frames")]),
            *(["--ros-adapter"] if getattr(args, "ros_adapter", False) else []),
            *(["--stock-sensors"] if getattr(args, "stock_sensors", False) else []),
        ],
        lab_name=args.name,
        pace=getattr(args, "pace", None),
        inventory_file=getattr(args, "inventory", None),
        label_checks=getattr(args, "label_checks", False),
    )


@contextmanager
def _ca_file(args: argparse.Namespace) -> Iterator[Path]:
    """Where the run writes the CA certificate: --ca-file, ./sila-labware-ca.pem for serve, else a
    `sila-labware-<command>-*` directory in the temp folder, removed when the block ends (however)."""
    if args.ca_file is not None or args.command == "serve":
        yield args.ca_file or Path("sila-labware-ca.pem")
        return
    with tempfile.TemporaryDirectory(prefix=f"sila-labware-{args.command}-") as scratch:
        yield Path(scratch) / "ca.pem"


def _interrupt_on_signals() -> None:
    """SIGINT and SIGTERM raise KeyboardInterrupt on the main thread, except while interrupts are
    held (a child being started, a deployment stopping): the run unwinds through its clean-up."""
    from sila_labware.deployment.processes import interrupt_between_starts

    signal.signal(signal.SIGINT, interrupt_between_starts)
    signal.signal(signal.SIGTERM, interrupt_between_starts)


def _start(args: argparse.Namespace) -> tuple[Deployment | None, _StopRequest]:
    """Start the deployment; None if it could not start (the reason is on stderr, and on stdout as
    JSON with --print-config) or was stopped while starting (then the stop request is set)."""
    from sila_labware.deployment.stack import Deployment

    stop = _StopRequest()
    stop.install()
    deployment = Deployment(_deployment_options(args, args.ca_file or Path("sila-labware-ca.pem")))
    try:
        deployment.start(should_stop=stop.event.is_set)
    except KeyboardInterrupt:
        stop.event.set()
        if args.print_config:
            JsonOutput.write_failure(
                "interrupted (SIGINT or SIGTERM) while starting", json_outcome.INTERRUPTED, 0
            )
        return None, stop
    except Exception as error:  # noqa: BLE001 - one line for the user, details in the log
        logger.debug("start failed", exc_info=True)
        sys.stderr.write(f"sila-labware: could not start: {error}\n")
        if args.print_config:
            JsonOutput.write_failure(f"could not start: {error}", json_outcome.START_FAILED, 1)
        return None, stop
    return deployment, stop


def serve(args: argparse.Namespace) -> int:
    deployment, stop = _start(args)
    if deployment is None:
        return 0 if stop.event.is_set() else 1
    try:
        listing = sys.stderr if args.print_config else sys.stdout  # stdout: the JSON alone
        print_servers(deployment, listing)
        if args.print_config == "json":
            write_config(deployment, sys.stdout)
        listing.write("serving; Ctrl-C stops\n")
        listing.flush()
        while not stop.event.wait(0.5):
            deployment.check_healthy()
        return 0
    except Exception as error:  # noqa: BLE001
        sys.stderr.write(f"sila-labware: {error}\n")
        return 1
    finally:
        deployment.stop()


def demo(args: argparse.Namespace) -> int:
    _interrupt_on_signals()
    with _ca_file(args) as ca_file:
        report, ending = _run_demo(args, ca_file)
    if args.record is not None and ending == _TRANSFERRED:
        try:
            write_recorded_pictures(args.record)
        except KeyboardInterrupt:
            ending = _INTERRUPTED
    for stop_signal in (signal.SIGINT, signal.SIGTERM):  # the outcome is printed whole
        signal.signal(stop_signal, signal.SIG_IGN)
    exit_code = INTERRUPTED_EXIT_CODE if ending == _INTERRUPTED else 0 if report.success else 1
    if args.json:
        if ending == _INTERRUPTED and not report.error:  # delivered, then stopped writing the pictures
            report.success, report.error = False, "interrupted (SIGINT or SIGTERM) while writing the pictures"
        kind = {_INTERRUPTED: json_outcome.INTERRUPTED, _NOT_STARTED: json_outcome.START_FAILED}.get(
            ending, json_outcome.FAILED
        )
        error = "" if report.success else report.error or "the plate was not delivered"
        JsonOutput.write(
            {**report.as_json_object(), **outcome_fields(error, kind if error else "", exit_code)}
        )
    elif ending != _NOT_STARTED:  # a start-up failure is the one line on stderr
        outcome = "plate delivered" if report.success else f"FAILED: {report.error}"
        error_mm = report.plate_position_error_mm
        detail = f" (position error {error_mm:.1f} mm)" if error_mm is not None else ""
        sys.stdout.write(
            f"{outcome}{detail}; {report.wall_seconds:.1f} s wall, {report.sim_seconds:.1f} s simulated\n"
        )
    sys.stdout.flush()
    return exit_code


_TRANSFERRED, _INTERRUPTED, _NOT_STARTED = "transferred", "interrupted", "not started"


def _run_demo(args: argparse.Namespace, ca_file: Path) -> tuple[DemoReport, str]:
    """Start, transfer, stop: the report (with the error of whatever failed) and how it ended
    (_TRANSFERRED: the transfer ran, successful or not). Never raises for a failure or an
    interrupt; always stops what it started."""
    from sila_labware.deployment.demo import DemoReport, run_demo
    from sila_labware.deployment.processes import interrupt_requested
    from sila_labware.deployment.stack import Deployment

    report, deployment, ending = DemoReport(), None, _NOT_STARTED
    try:
        deployment = Deployment(_deployment_options(args, ca_file))
        deployment.start()
        ending = _TRANSFERRED
        print_servers(deployment, sys.stderr)
        report = run_demo(deployment, progress_stream=sys.stderr)
        if interrupt_requested():  # a library turned the KeyboardInterrupt into its own error
            raise KeyboardInterrupt
    except KeyboardInterrupt:
        ending = _INTERRUPTED
        report.success = False
        report.error = "interrupted (SIGINT or SIGTERM): the transfer was abandoned and everything stopped"
        sys.stderr.write(f"\nsila-labware: {report.error}\n")
    except Exception as error:  # noqa: BLE001 - one line for the user, details in the log
        logger.debug("demo failed", exc_info=True)
        report.error = f"{'demo failed' if ending == _TRANSFERRED else 'could not start'}: {error}"
        sys.stderr.write(f"sila-labware: {report.error}\n")
    finally:
        if deployment is not None:
            deployment.stop()
    return report, ending


def bluesky_demo(args: argparse.Namespace) -> int:
    """Robot side only (no SiLA): the beamline paper's plan on a RunEngine against the simulation."""
    from ros_bridge.bluesky.demo import run_bluesky_demo
    from sila_labware.deployment.processes import ProcessGroup, ros_environment
    from sila_labware.deployment.stack import choose_domain_id, join_ros_domain, start_robot_side

    domain_id = choose_domain_id(args.domain_id)
    join_ros_domain(domain_id)
    with ProcessGroup(ros_environment(domain_id), args.log_dir) as children:
        start_robot_side(children, args.world)
        sys.stderr.write(f"robot side started (ROS domain {domain_id}); running the Bluesky plan\n")
        exit_code = run_bluesky_demo(
            args.world, domain_id=domain_id, ready_timeout_s=args.ready_timeout, progress_bar=True
        )
    outcome = "the plate is back in its starting nest" if exit_code == 0 else "FAILED (the reason is above)"
    sys.stderr.write(f"bluesky demo: {outcome}\n")
    return exit_code


def _bench(args: argparse.Namespace) -> int:
    # Ctrl-C and SIGTERM unwind the running trial: its robot side (own sessions, so a terminal's
    # Ctrl-C never reaches it) is stopped on the way out instead of being left running.
    _interrupt_on_signals()
    with _ca_file(args) as ca_file:
        return bench_command(args, _deployment_options(args, ca_file))


COMMANDS = {
    "serve": serve,
    "demo": demo,
    "bluesky-demo": bluesky_demo,
    "bench": _bench,
    "world": world_command,
}


def main(argv: Sequence[str] | None = None) -> int:
    arguments = sys.argv[1:] if argv is None else list(argv)
    as_json = json_outcome.json_requested(arguments)
    JsonOutput.reset()
    parser = build_parser()
    try:
        args = parser.parse_args(arguments)
        _validate(parser, args)
    except UsageError as error:  # its line is on stderr already
        if as_json:
            JsonOutput.write_failure(error.message, json_outcome.USAGE, 2)
        return 2
    logging.basicConfig(
        level=logging.INFO if getattr(args, "verbose", False) else logging.WARNING,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
    )
    # sila2 logs every error a client receives as a traceback: a refusal becomes one WARNING line
    install_refusal_log_filter()
    if args.command == "bluesky-demo":
        # bluesky's own loggers report every state change at INFO
        logging.getLogger("bluesky").setLevel(logging.INFO if args.verbose else logging.WARNING)
    try:
        return COMMANDS[args.command](args)
    except KeyboardInterrupt:  # a further Ctrl-C after the run was stopped and cleaned up
        if as_json:
            JsonOutput.write_failure(
                "interrupted (SIGINT or SIGTERM)", json_outcome.INTERRUPTED, INTERRUPTED_EXIT_CODE
            )
        return INTERRUPTED_EXIT_CODE
    except Exception as error:
        if not as_json:
            raise
        logger.exception("%s failed", args.command)  # a bug: the traceback on stderr
        JsonOutput.write_failure(f"{type(error).__name__}: {error}", json_outcome.INTERNAL, 1)
        return 1


if __name__ == "__main__":
    sys.exit(main())
