"""Run one SiLA server on its own against a robot side that is already running (simulated or real).

`python -m sila_labware.servers.robot_server` and
`python -m sila_labware.servers.station_server --station NAME`
use this: they start no child processes, only the ROS bridge (in the ROS domain of the
environment) and one server, and stop on SIGINT/SIGTERM. This is the path for a real TIAGo++
whose own ROS 2 action servers implement labware_interfaces. Nothing supervises the bridge here:
if its ROS thread ends, the server exits 1 naming why (whatever started it should start it again)
rather than refuse every command for ever.
"""

from __future__ import annotations

import argparse
import logging
import signal
import sys
import threading
from collections.abc import Callable, Sequence
from pathlib import Path

from sila2.server import SilaServer

from labware_model.workcell import WorkcellDescription
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime
from sila_labware.servers.refusal_log import install_refusal_log_filter
from sila_labware.servers.serving import start_sila_server, stop_sila_server
from sila_labware.servers.tls import CertificateAuthority

logger = logging.getLogger(__name__)

ServerFactory = Callable[[RobotLink, WorkcellDescription, argparse.Namespace], SilaServer]


def standalone_parser(prog: str, default_port: int) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=prog, description=__doc__.splitlines()[0])
    parser.add_argument("--host", default="127.0.0.1", help="address to bind (default: %(default)s)")
    parser.add_argument("--port", type=int, default=default_port, help="port (default: %(default)s)")
    parser.add_argument(
        "--insecure", action="store_true", help="no TLS (tests only; the standard forbids it)"
    )
    parser.add_argument("--ca-file", type=Path, default=Path(f"{prog.split('.')[-1]}-ca.pem"))
    parser.add_argument("--no-discovery", action="store_true", help="do not announce the server (mDNS)")
    parser.add_argument(
        "--ready-timeout", type=float, default=60.0, help="seconds to wait for the robot side"
    )
    return parser


def run_standalone(
    parser: argparse.ArgumentParser, build_server: ServerFactory, argv: Sequence[str] | None
) -> int:
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    install_refusal_log_filter()
    stop = threading.Event()
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    runtime = RosRuntime("sila_labware_standalone").start()
    server: SilaServer | None = None
    try:
        link = RobotLink(runtime)
        link.wait_until_ready(args.ready_timeout)
        server = build_server(link, link.describe_workcell(), args)
        if args.insecure:
            logger.warning("serving WITHOUT encryption (--insecure): for tests only")
        authority = None if args.insecure else CertificateAuthority()
        start_sila_server(server, args.host, args.port, authority=authority, discovery=not args.no_discovery)
        if authority is not None:
            authority.write_certificate(args.ca_file)
        sys.stdout.write(f"{server.server_name} at {args.host}:{args.port}\n")
        sys.stdout.flush()
        while not stop.wait(0.5):  # until Ctrl-C or SIGTERM, or the bridge can no longer work
            if runtime.failure:
                raise RuntimeError(f"the bridge's ROS thread ended ({runtime.failure})")
        return 0
    except Exception as error:  # noqa: BLE001 - one line for the user
        sys.stderr.write(f"{parser.prog}: {error}\n")
        return 1
    finally:
        if server is not None:
            stop_sila_server(server, grace_period=0.5)
        runtime.stop()
