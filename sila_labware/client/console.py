"""What a script on a terminal needs around the client: connection options, handover arguments,
and a progress display.

    parser = argparse.ArgumentParser()
    add_connection_arguments(parser)       # --robot, --station, --ca-file, --insecure
    args = parser.parse_args(argv)
    with client_from_arguments(args) as robot:
        robot.transfer(("station_a", 1), ("station_b", 1), on_progress=StepPrinter())

The defaults are what `sila-labware serve` uses with the bundled world: the robot on
127.0.0.1:50052, one station per port after it, the CA certificate in ./sila-labware-ca.pem.

Threads: the caller's; a StepPrinter is called on the thread running the client's method.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TextIO

from labware_model.holders import Nest
from sila_labware.client.errors import LabwareTransferError
from sila_labware.client.records import Address
from sila_labware.client.steps import StepProgress
from sila_labware.client.transfer_client import LabwareTransferClient

DEFAULT_ROBOT = "127.0.0.1:50052"
DEFAULT_STATIONS = ("127.0.0.1:50053", "127.0.0.1:50054")
DEFAULT_CA_FILE = Path("sila-labware-ca.pem")


def address(text: str) -> Address:
    """ "HOST:PORT" -> (host, port); an argparse type."""
    host, _, port = text.rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise argparse.ArgumentTypeError(f"{text!r} is not HOST:PORT")
    return host, int(port)


def handover(text: str) -> Nest:
    """ "station_a/1" -> Nest("station_a", 1), whose str() is that text again; an argparse type."""
    station, _, sub_position = text.rpartition("/")
    if not station or not sub_position.isdigit() or int(sub_position) < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not STATION/SUB_POSITION (e.g. station_a/1)")
    return Nest(station, int(sub_position))


def add_connection_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--robot", type=address, default=address(DEFAULT_ROBOT), metavar="HOST:PORT",
        help=f"the robot's SiLA server (default: {DEFAULT_ROBOT})",
    )  # fmt: skip
    parser.add_argument(
        "--station", type=address, action="append", dest="stations", metavar="HOST:PORT",
        help=f"a station's SiLA server; repeat for each (default: {' '.join(DEFAULT_STATIONS)})",
    )  # fmt: skip
    parser.add_argument(
        "--ca-file", type=Path, default=DEFAULT_CA_FILE,
        help="the CA certificate `serve` wrote (default: %(default)s)",
    )  # fmt: skip
    parser.add_argument("--insecure", action="store_true", help="no TLS (a server started with --insecure)")


def client_from_arguments(args: argparse.Namespace) -> LabwareTransferClient:
    """The client for the options `add_connection_arguments` added; LabwareTransferError (or
    ServerUnreachable) says what is missing."""
    stations = args.stations or [address(text) for text in DEFAULT_STATIONS]
    root_certs = None
    if not args.insecure:
        try:
            root_certs = args.ca_file.read_bytes()
        except OSError as error:
            raise LabwareTransferError(
                f"cannot read the CA certificate {args.ca_file} ({error.strerror}); `serve` prints "
                "where it wrote it: pass that with --ca-file"
            ) from error
    return LabwareTransferClient(args.robot, stations, root_certs=root_certs, insecure=args.insecure)


class ProgressLine:
    """One live line on a terminal: step name, bar, remaining time; one plain line per finished
    step. On a stream that is not a terminal (a log, a pipe) only the finished steps appear."""

    def __init__(self, stream: TextIO | None) -> None:
        self._stream = stream
        self._interactive = bool(stream is not None and stream.isatty())

    def show(self, step: str, progress: float, remaining_s: float | None) -> None:
        if self._stream is None or not self._interactive:
            return
        filled = int(round(20 * progress))
        remaining = f"{remaining_s:5.1f} s left" if remaining_s is not None else ""
        self._stream.write(
            f"\r{step:<48} [{'#' * filled}{'.' * (20 - filled)}] {100 * progress:5.1f} % {remaining}"
        )
        self._stream.flush()

    def done(self, step: str, wall_s: float, sim_s: float | None = None) -> None:
        if self._stream is None:
            return
        prefix = "\r" if self._interactive else ""
        simulated = f", {sim_s:6.1f} s simulated" if sim_s is not None else ""
        rubout = " " * 12 if self._interactive else ""  # the end of a longer live line
        self._stream.write(f"{prefix}{step:<48} done in {wall_s:6.1f} s{simulated}{rubout}\n")
        self._stream.flush()


class StepPrinter:
    """An `on_progress` callback that draws a ProgressLine with each step's wall time."""

    def __init__(self, stream: TextIO | None = None) -> None:
        self._line = ProgressLine(stream if stream is not None else sys.stdout)

    def __call__(self, record: StepProgress) -> None:
        if record.done:
            self._line.done(record.step, record.elapsed_s)
        else:
            self._line.show(record.step, record.progress, record.remaining_s)
