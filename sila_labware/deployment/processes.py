"""Child processes of `sila-labware serve`: the robot side's ROS nodes, started and stopped as a group.

Each child runs in its own process group (new session), so stopping it also stops anything it
started; stop sends SIGTERM to every group, waits, then SIGKILLs what is left. Every child gets
the ROS environment of this deployment (domain id, localhost-only discovery).

A child's output goes to `<log_dir>/<name>.log`, or without a log directory to an anonymous
temporary file (a few kB per transfer), so that a child that dies can always say why.

Threads: used from the thread that runs the deployment (the CLI's main thread).
"""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from types import FrameType
from typing import IO

from sila_labware.deployment.prewarmed import ForkedChild, fork_python_module

logger = logging.getLogger(__name__)

FASTDDS_PROFILE = Path(__file__).with_name("fastdds_profile.xml")
"""Quick discovery: a deployment started in 2 s instead of 4 to 5 s (see the file)."""


def ros_environment(domain_id: int, base: Mapping[str, str] | None = None) -> dict[str, str]:
    """The environment for ROS processes of one deployment: its own domain, this machine only."""
    environment = dict(os.environ if base is None else base)
    environment["ROS_DOMAIN_ID"] = str(domain_id)
    environment.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    environment.setdefault("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")
    environment.setdefault("FASTRTPS_DEFAULT_PROFILES_FILE", str(FASTDDS_PROFILE))
    environment.setdefault("PYTHONUNBUFFERED", "1")
    return environment


INPUT_REFUSED_EXIT_CODE = 2
"""A child exiting with this code refused its input (a bad world file, bad arguments) and wrote why
as its last line of output; that line alone is the message (e.g. `sila-labware serve` shows it)."""

LOG_TAIL_BYTES = 64 * 1024
KILL_WAIT_S = 2.0
"""How long `stop` waits for a child after SIGKILL."""


class ChildExited(RuntimeError):
    """A child process ended while the deployment needed it."""


@dataclass
class Child:
    name: str
    popen: subprocess.Popen | ForkedChild
    log_path: Path | None
    output_file: IO[bytes] | None = None
    """The anonymous file the child writes to when there is no log directory."""

    @property
    def running(self) -> bool:
        return self.popen.poll() is None

    @property
    def pid(self) -> int:
        return self.popen.pid

    def log_tail(self, lines: int = 15) -> str:
        if self.log_path is not None and self.log_path.exists():
            text = self.log_path.read_text(errors="replace")
        elif self.output_file is not None and not self.output_file.closed:
            # pread: the child shares this file's offset, so never seek it.
            descriptor = self.output_file.fileno()
            size = os.fstat(descriptor).st_size
            start = max(0, size - LOG_TAIL_BYTES)
            text = os.pread(descriptor, size - start, start).decode(errors="replace")
        else:
            return ""
        return "\n".join(text.splitlines()[-lines:])


# Main thread only (signal handlers run there): an interrupt that arrives while interrupts are
# held (a child being started, the deployment stopping) waits until the hold ends.
_hold_depth = 0
_interrupt_pending = False
_interrupt_seen = False


def interrupt_between_starts(_signum: int, _frame: FrameType | None) -> None:
    """Signal handler raising KeyboardInterrupt, but never while interrupts are held
    (`interrupts_held`): between starting a child (own session, so no terminal signal reaches it)
    and registering it, which left a sequencer running, or while a deployment stops."""
    global _interrupt_pending, _interrupt_seen
    _interrupt_seen = True
    if _hold_depth:
        _interrupt_pending = True
        return
    raise KeyboardInterrupt


def interrupt_requested() -> bool:
    """True once `interrupt_between_starts` was called. Ask this after a run, not only whether
    KeyboardInterrupt came out of it: a library may turn the exception into one of its own (the
    sila2 client reports a call interrupted by it as ServerUnreachable)."""
    return _interrupt_seen


@contextmanager
def interrupts_held() -> Iterator[None]:
    """Hold `interrupt_between_starts` for the block; an interrupt that came meanwhile is raised as
    KeyboardInterrupt when the block ends normally (if it raises, the interrupt stays pending until
    the next hold ends). Does nothing on other threads than the main thread, which alone gets
    signals."""
    global _hold_depth, _interrupt_pending
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _hold_depth += 1
    try:
        yield
    finally:
        _hold_depth -= 1
    if _hold_depth == 0 and _interrupt_pending:
        _interrupt_pending = False
        raise KeyboardInterrupt


class ProcessGroup:
    """Children started together and stopped together."""

    def __init__(
        self, environment: Mapping[str, str], log_dir: Path | None = None, prewarmed: bool = False
    ) -> None:
        self._environment = dict(environment)
        self._log_dir = log_dir
        self._prewarmed = prewarmed
        """Fork children from a process that imported them already (prewarmed.py), not spawn them."""
        self.children: list[Child] = []
        self._starts: dict[str, int] = {}  # name -> how often it was started (restarts keep their logs)

    def start_python_module(self, name: str, module: str, arguments: Sequence[str]) -> Child:
        """Run `python -m module arguments...` with this interpreter; output goes to a log file."""
        argv = [sys.executable, "-m", module, *arguments]
        log_path = None
        output_file = None
        if self._log_dir is not None:
            self._log_dir.mkdir(parents=True, exist_ok=True)
            log_path = self._log_dir / f"{name}.log"
            runs = self._starts.get(name, 0)
            if runs and log_path.exists():  # a restart: keep what the run before said, as name.N.log
                log_path.replace(self._log_dir / f"{name}.{runs}.log")
            self._starts[name] = runs + 1
            output = log_path.open("wb")
        else:
            output = output_file = tempfile.TemporaryFile(prefix=f"sila-labware-{name}-")
        with interrupts_held():
            try:
                popen = (
                    fork_python_module(module, arguments, self._environment, output.fileno())
                    if self._prewarmed
                    else subprocess.Popen(
                        argv,
                        env=self._environment,
                        stdout=output,
                        stderr=subprocess.STDOUT,
                        stdin=subprocess.DEVNULL,
                        start_new_session=True,
                    )
                )
                child = Child(name, popen, log_path, output_file)
                self.children.append(child)
            finally:
                if output_file is None:
                    output.close()  # the child holds its own descriptor
            logger.info("started %s (pid %d): %s", name, popen.pid, " ".join(argv))
        return child

    def check_running(self) -> None:
        """Raise ChildExited naming the first child that ended (with the end of its log)."""
        for child in self.children:
            code = child.popen.poll()
            if code is not None:
                tail = child.log_tail()
                if code == INPUT_REFUSED_EXIT_CODE and tail:
                    raise ChildExited(f"{child.name}: {tail.splitlines()[-1]}")
                raise ChildExited(
                    f"{child.name} exited with code {code}"
                    + (f"; last lines of its log:\n{tail}" if tail else "")
                )

    def stacks(self, wait_s: float = 1.0, lines: int = 60) -> str:
        """Have every running child write its threads' stacks into its log (SIGUSR1: the robot
        side's processes register faulthandler for it) and return the ends of their logs: what a
        child that did not come up in time was doing."""
        running = [child for child in self.children if child.running]
        for child in running:
            try:
                os.kill(child.pid, signal.SIGUSR1)
            except ProcessLookupError:
                pass
        time.sleep(wait_s)
        return "\n".join(f"--- {child.name} (pid {child.pid}):\n{child.log_tail(lines)}" for child in running)

    def terminate(self) -> None:
        """SIGTERM every child's process group and return at once (`stop` waits for them)."""
        for child in list(self.children):
            _signal_group(child, signal.SIGTERM)

    def stop(self, timeout_s: float = 3.0) -> None:
        """SIGTERM every child's process group, wait up to `timeout_s`, then SIGKILL the rest."""
        self.terminate()
        deadline = time.monotonic() + timeout_s
        for child in self.children:
            try:
                child.popen.wait(max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                logger.warning("%s did not stop on SIGTERM within %.1f s: killing it", child.name, timeout_s)
                _signal_group(child, signal.SIGKILL)
                try:
                    child.popen.wait(KILL_WAIT_S)
                except subprocess.TimeoutExpired:  # stuck in the kernel: nothing more to do here
                    logger.error(
                        "%s (pid %d) survived SIGKILL for %.1f s", child.name, child.pid, KILL_WAIT_S
                    )
        for child in self.children:
            if child.output_file is not None:
                child.output_file.close()
        self.children.clear()

    def __enter__(self) -> ProcessGroup:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.stop()


def _signal_group(child: Child, signal_number: int) -> None:
    if child.popen.poll() is not None:
        return
    try:
        os.killpg(child.popen.pid, signal_number)  # the child leads its own group (new session)
    except ProcessLookupError:
        pass
