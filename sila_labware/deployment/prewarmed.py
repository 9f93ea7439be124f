"""Robot-side children forked from a process that has imported their code already.

Why: a campaign starts a fresh robot side for every trial (`bench`, 200 times), and each fresh
`python -m tiago_twin` spends about 0.6 s of CPU importing rclpy, PyBullet, pinocchio,
OpenCV and pydantic before it reads its world; the sequencer about 0.2 s. A fork server, started
once per process that asks (`python -m sila_labware.deployment.prewarmed`), imports those modules
and then forks each child from that interpreter. Nothing else is shared: the server never
initialises ROS or connects to PyBullet, so each child builds its node, its simulation and its DDS
participants from scratch, as a fresh process would.

A forked child gets what `ProcessGroup.start_python_module` gives a spawned one: its own session
(a signal to its group reaches it alone), the deployment's environment, its output on the log file
(the descriptor travels over the server's socket), its `python -m` argument vector, and its exit
code as the module's `main` returned it. The asking process becomes the child's parent: it is a
child subreaper (Linux prctl), the server forks through a short-lived intermediate, and the
orphaned child is re-parented to it, so `ForkedChild` can poll and wait for it like a
`subprocess.Popen` (the part of Popen the deployment uses). What differs: `ps` shows a forked
child with the fork server's command line and environment (its /proc/PID/cmdline and environ) but
with its own name (/proc/PID/comm, `ps -o comm`): `sim_node`, `sequencer`.

Threads: `fork_python_module` from any thread of the asking process (one request at a time).
"""

from __future__ import annotations

import ctypes
import json
import logging
import os
import runpy
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Mapping, Sequence

logger = logging.getLogger(__name__)

PRELOADED_MODULES = ("tiago_twin.startup", "tiago_sim.physics.simulation", "tiago_sim.sequencer.startup")
"""What the fork server imports once: the robot side's nodes and their heavy dependencies."""
PR_SET_CHILD_SUBREAPER = 36
PR_SET_NAME = 15
MESSAGE_BYTES = 1 << 20
ORPHANED = "not started: the process that asked for it ended before it was started"


class ForkedChild:
    """A forked robot-side process, seen as the deployment sees a `subprocess.Popen`."""

    def __init__(self, pid: int, argv: Sequence[str]) -> None:
        self.pid = pid
        self.args = list(argv)
        self.returncode: int | None = None
        self._lock = threading.Lock()

    def poll(self) -> int | None:
        with self._lock:
            if self.returncode is None:
                try:
                    pid, status = os.waitpid(self.pid, os.WNOHANG)
                except ChildProcessError:  # reaped elsewhere: it ended, how is unknown
                    self.returncode = -1
                else:
                    if pid == self.pid:
                        self.returncode = os.waitstatus_to_exitcode(status)
            return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        deadline = None if timeout is None else time.monotonic() + timeout
        while self.poll() is None:
            if deadline is not None and time.monotonic() >= deadline:
                raise subprocess.TimeoutExpired(self.args, timeout or 0.0)
            time.sleep(0.01)
        return int(self.returncode)


class _ForkServer:
    """The client end: one server process per asking process, started at the first request."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._socket: socket.socket | None = None
        self._process: subprocess.Popen | None = None

    def fork(
        self, module: str, arguments: Sequence[str], environment: Mapping[str, str], output: int
    ) -> ForkedChild:
        request = json.dumps(
            {
                "module": module,
                "arguments": list(arguments),
                "environment": dict(environment),
                "asker": os.getpid(),
            }
        )
        with self._lock:
            connection = self._connection()
            socket.send_fds(connection, [request.encode()], [output])
            reply = connection.recv(MESSAGE_BYTES)
        if not reply:
            raise RuntimeError("the robot side's fork server ended")
        answer = json.loads(reply)
        if "error" in answer:
            raise RuntimeError(f"the robot side's fork server could not start {module}: {answer['error']}")
        return ForkedChild(int(answer["pid"]), [sys.executable, "-m", module, *arguments])

    def _connection(self) -> socket.socket:
        if self._socket is not None and self._process is not None and self._process.poll() is None:
            return self._socket
        if ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) != 0:
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_CHILD_SUBREAPER) failed")
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        self._process = subprocess.Popen(
            [sys.executable, "-m", __name__, str(theirs.fileno())],
            pass_fds=[theirs.fileno()],
            stdin=subprocess.DEVNULL,
        )
        theirs.close()
        self._socket = ours
        logger.info("robot-side fork server started (pid %d)", self._process.pid)
        return ours


_server = _ForkServer()


def fork_python_module(
    module: str, arguments: Sequence[str], environment: Mapping[str, str], output: int
) -> ForkedChild:
    """Fork `module` (run as __main__ with `arguments`) from the fork server; its output goes to
    the open file descriptor `output` (the caller keeps its own)."""
    return _server.fork(module, arguments, environment, output)


# --- the server process ---------------------------------------------------------------------


def _run_module(request: dict, output: int, intermediate: int) -> None:
    """In the forked child (its own session already): become what `python -m module arguments...`
    would have been; or end at once if the asking process ended before the child was re-parented
    to it (a Ray worker lost mid-start): re-parented to init, the node's check that its starter is
    gone would compare against init and never fire (an orphaned sequencer outlived a CI run)."""
    while os.getppid() == intermediate:  # wait until re-parented to the asking process
        time.sleep(0.001)
    parent = os.getppid()
    if parent != request["asker"]:
        os.write(output, f"{ORPHANED}: pid {request['asker']} (the parent is pid {parent})\n".encode())
        raise SystemExit(1)
    name = request["module"].rsplit(".", 1)[-1].encode()[:15]
    ctypes.CDLL(None).prctl(PR_SET_NAME, ctypes.c_char_p(name), 0, 0, 0)
    os.environ.clear()
    os.environ.update(request["environment"])
    os.dup2(output, 1)
    os.dup2(output, 2)
    os.close(output)
    sys.stdout.reconfigure(line_buffering=True)
    sys.argv = [request["module"], *request["arguments"]]
    runpy.run_module(request["module"], run_name="__main__", alter_sys=True)


def _serve_one(connection: socket.socket, request: dict, output: int) -> None:
    """Fork an intermediate that forks the child and ends as soon as the child leads its own
    session (so a signal to the group the answer names reaches it); answer with the child's pid."""
    reader, writer = os.pipe()
    intermediate = os.fork()
    if intermediate == 0:  # the intermediate
        os.close(reader)
        me = os.getpid()  # before the fork: the child may be re-parented before it could ask
        in_session_reader, in_session_writer = os.pipe()
        child = os.fork()
        if child == 0:
            os.setsid()
            os.close(in_session_reader)
            os.close(in_session_writer)  # end of file for the intermediate: the session exists
            os.close(writer)
            connection.close()
            code = 1
            try:
                _run_module(request, output, me)
                code = 0
            except SystemExit as end:
                code = end.code if isinstance(end.code, int) else (0 if end.code is None else 1)
            except BaseException:  # noqa: BLE001 - the child's last words go to its log
                import traceback

                traceback.print_exc()
            finally:
                sys.stdout.flush()
                sys.stderr.flush()
                os._exit(code)
        os.close(in_session_writer)
        os.read(in_session_reader, 1)
        os.write(writer, str(child).encode())
        os._exit(0)
    os.close(writer)
    os.close(output)
    pid = os.read(reader, 32).decode()
    os.close(reader)
    os.waitpid(intermediate, 0)
    connection.send(json.dumps({"pid": int(pid)}).encode())


def serve(descriptor: int) -> None:
    """Import the robot side once, then fork a child per request until the asking process goes."""
    for module in PRELOADED_MODULES:
        __import__(module)
    connection = socket.socket(fileno=descriptor)
    while True:
        try:
            message, descriptors, _flags, _address = socket.recv_fds(connection, MESSAGE_BYTES, 1)
        except OSError:
            return
        if not message:
            return
        try:
            _serve_one(connection, json.loads(message), descriptors[0])
        except Exception as error:  # noqa: BLE001 - reported to the asking process, server stays
            connection.send(json.dumps({"error": f"{type(error).__name__}: {error}"}).encode())


if __name__ == "__main__":
    serve(int(sys.argv[1]))
