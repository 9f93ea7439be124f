"""One rclpy context, one node and one executor, spun on one thread.

Threads: `RosRuntime.start()` creates a private rclpy context, a node and a single-threaded
executor, and starts ONE daemon thread (the "ROS thread") that spins the executor. Every
rclpy object (clients, subscriptions, goal handles) is created and used on that thread only:
other threads (SiLA handler threads, the CLI's main thread) hand work over with `submit()`,
which returns a `concurrent.futures.Future`, and wait on that future with a timeout. No thread
other than the ROS thread ever spins, and no other thread destroys what the ROS thread uses: the
ROS thread tears the node, the executor and the context down itself, on its way out.

rclpy's own action client is not safe to call from a second thread while the executor spins
(it registers the pending goal after sending the request), hence the hand-over queue: a guard
condition wakes the executor, whose callback drains the queue on the ROS thread.

How the ROS thread ends: `stop()` asks it to; or an rclpy callback raises (rclpy re-raises it
from `spin_once`), or the context is shut down from outside. In the last two cases `failure`
says why. Either way every call waiting in the queue fails with BridgeError at once, every later
`submit` is refused naming the reason, and the end listeners are told (`add_end_listener`: the
action callers end their open goals there, since no answer can reach them any more); nothing
restarts the thread. An owner that must outlive that (the deployment's supervisor) watches
`failure` and builds a new runtime.
"""

from __future__ import annotations

import concurrent.futures
import logging
import queue
import sys
import threading
import traceback
from collections.abc import Callable
from typing import Any, TypeVar

import rclpy
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from ros_bridge.errors import BridgeError, BridgeTimeout

logger = logging.getLogger(__name__)

T = TypeVar("T")

SPIN_PERIOD_S = 0.1
"""How often the spin loop looks at the stop flag when nothing else wakes it."""


class RosRuntime:
    """Owns the rclpy context, node and executor; runs submitted callables on the ROS thread."""

    def __init__(self, node_name: str = "sila_bridge", domain_id: int | None = None) -> None:
        self._node_name = node_name
        self._domain_id = domain_id
        self._context: Context | None = None
        self._node: Node | None = None
        self._executor: SingleThreadedExecutor | None = None
        self._thread: threading.Thread | None = None
        self._pending_calls: queue.SimpleQueue[tuple[Callable[[], Any], concurrent.futures.Future]] = (
            queue.SimpleQueue()
        )
        self._queue_lock = threading.Lock()  # submit vs. the ROS thread closing the queue
        self._queue_closed = False
        self._wake = None
        self._stopping = threading.Event()
        self._failure = ""
        self._owned: list[Any] = []  # entities the node does not destroy itself (action clients)
        self._end_listeners: list[Callable[[str], None]] = []
        self._end_reason = ""  # set once, when the end listeners are told

    @property
    def node(self) -> Node:
        """The bridge node. Use it only on the ROS thread (inside `submit`)."""
        if self._node is None:
            raise BridgeError("the ROS runtime is not started")
        return self._node

    @property
    def running(self) -> bool:
        """True while the ROS thread spins and nobody asked it to stop."""
        return self.thread_alive and not self._stopping.is_set() and not self._queue_closed

    @property
    def thread_alive(self) -> bool:
        """True while the ROS thread exists (also while it is stopping)."""
        return self._thread is not None and self._thread.is_alive()

    @property
    def failure(self) -> str:
        """Why the ROS thread ended by itself ("RuntimeError: ..." from a callback, or "the rclpy
        context was shut down"); empty while it runs, and after an ordinary `stop()`."""
        return self._failure

    def own(self, entity: T) -> T:
        """Destroy `entity` (anything with `destroy()`) with the node: rclpy's destroy_node skips
        action clients, and one left alive keeps the node's DDS participant alive with it."""
        self._owned.append(entity)
        return entity

    def add_end_listener(self, listener: Callable[[str], None]) -> None:
        """Call `listener(reason)` once when the ROS thread ends ("the ROS runtime was stopped",
        "the ROS thread ended (RuntimeError: ...)"), or at once if it has. It runs on the ROS
        thread on its way out, or on the thread of `stop()` if the ROS thread does not end in time:
        it must not touch rclpy objects. Exceptions are logged."""
        with self._queue_lock:
            reason = self._end_reason
            if not reason:
                self._end_listeners.append(listener)
                return
        _tell_end(listener, reason)

    def on_ros_thread(self) -> bool:
        return threading.current_thread() is self._thread

    def start(self) -> RosRuntime:
        """Create context, node and executor, and start the ROS thread. Returns self."""
        if self._thread is not None:
            raise BridgeError("the ROS runtime was already started")
        self._context = Context()
        # No signal handlers: the owner of the process (CLI, tests) decides what SIGINT does.
        rclpy.init(
            context=self._context,
            domain_id=self._domain_id,
            signal_handler_options=SignalHandlerOptions.NO,
        )
        self._node = Node(self._node_name, context=self._context)
        self._executor = SingleThreadedExecutor(context=self._context)
        self._executor.add_node(self._node)
        self._wake = self._node.create_guard_condition(self._drain_pending_calls)
        self._thread = threading.Thread(target=self._spin, name=f"ros-{self._node_name}", daemon=True)
        self._thread.start()
        logger.info("ROS runtime %s started (domain %s)", self._node_name, self._context.get_domain_id())
        return self

    def stop(self, timeout_s: float = 3.0) -> None:
        """Ask the ROS thread to stop and wait up to `timeout_s` for it. Safe to call twice, and
        after the thread ended by itself.

        The ROS thread destroys the node (while its context is still valid, so that its DDS
        entities and participant go at once: destroyed after shutdown they linger until garbage
        collection, and a process that starts runtime after runtime, like the bench, piles up
        participants), then shuts the context down, before it ends.

        If the ROS thread does not end within `timeout_s` (a callback that blocks), this returns
        anyway, with a warning, and touches no rclpy object: they stay the ROS thread's, which
        tears them down when its callback returns; it is a daemon thread, so it never keeps the
        process from exiting. Either way the calls still queued fail with BridgeError, and the
        runtime refuses new ones."""
        if self._thread is None or self._stopping.is_set():
            return
        self._stopping.set()
        if self.on_ros_thread():
            return  # from a callback: the spin loop sees the flag when the callback returns
        with self._queue_lock:
            if not self._queue_closed:
                self._wake.trigger()  # spin_once returns now rather than after SPIN_PERIOD_S
        self._thread.join(timeout_s)  # the spin loop looks at the flag every SPIN_PERIOD_S
        if self._thread.is_alive():
            logger.warning(
                "the ROS thread did not stop within %.1f s; it tears its node down when it does",
                timeout_s,
            )
        self._close()
        logger.info("ROS runtime %s stopped", self._node_name)

    def __enter__(self) -> RosRuntime:
        return self.start()

    def __exit__(self, *exc_info: object) -> None:
        self.stop()

    def submit(self, call: Callable[[], T]) -> concurrent.futures.Future[T]:
        """Run `call` on the ROS thread; its return value (or exception) lands in the future."""
        result: concurrent.futures.Future[T] = concurrent.futures.Future()
        if self.on_ros_thread():
            _run_into(call, result)
            return result
        with self._queue_lock:  # the ROS thread closes the queue before it destroys the guard
            if not self.running:
                result.set_exception(BridgeError(self._not_running()))
                return result
            self._pending_calls.put((call, result))
            self._wake.trigger()
        return result

    def call(self, call: Callable[[], T], timeout_s: float = 5.0) -> T:
        """Run `call` on the ROS thread and wait for its return value.

        A call the ROS thread has not started within `timeout_s` is withdrawn, so that a goal whose
        sending was reported as failed can never be sent later behind the caller's back."""
        future = self.submit(call)
        try:
            return future.result(timeout=timeout_s)
        except concurrent.futures.TimeoutError as error:
            if future.cancel():
                raise BridgeTimeout(
                    f"the ROS thread did not answer within {timeout_s:.1f} s (the call was withdrawn); "
                    f"it was at: {self._ros_thread_at()}"
                ) from error
        try:  # it started just now: let it finish rather than leave its effect unknown
            return future.result(timeout=timeout_s)
        except concurrent.futures.TimeoutError as error:
            waited = 2 * timeout_s
            raise BridgeTimeout(f"the ROS thread did not finish a call within {waited:.1f} s") from error

    def _ros_thread_at(self) -> str:
        """Where the ROS thread is now (its innermost frames), so that a call it never started
        says whether it was blocked in a callback or waiting in rcl with the call unseen."""
        frame = sys._current_frames().get(self._thread.ident) if self._thread is not None else None
        if frame is None:
            return "(the ROS thread has ended)"
        frames = traceback.extract_stack(frame)[-4:]
        return " <- ".join(f"{f.name} ({f.filename.rsplit('/', 1)[-1]}:{f.lineno})" for f in reversed(frames))

    def _not_running(self) -> str:
        if self._failure:
            return f"the ROS runtime is not running: its ROS thread ended ({self._failure})"
        return "the ROS runtime is not running"

    def _close(self) -> None:
        """Refuse new calls, fail the queued ones, tell the end listeners (once). Pure Python: on
        the ROS thread as it ends, or on the thread of a `stop()` that gave up waiting for it."""
        with self._queue_lock:
            self._queue_closed = True
            told = bool(self._end_reason)
            if not told:
                failure = self._failure
                self._end_reason = (
                    f"the ROS thread ended ({failure})" if failure else "the ROS runtime was stopped"
                )
            listeners, self._end_listeners = self._end_listeners, []
        self._fail_pending_calls(self._not_running())
        for listener in listeners:
            _tell_end(listener, self._end_reason)

    def _drain_pending_calls(self) -> None:
        while True:
            try:
                call, result = self._pending_calls.get_nowait()
            except queue.Empty:
                return
            if result.set_running_or_notify_cancel():
                _run_into(call, result)

    def _fail_pending_calls(self, reason: str) -> None:
        while True:
            try:
                _call, result = self._pending_calls.get_nowait()
            except queue.Empty:
                return
            if result.set_running_or_notify_cancel():
                result.set_exception(BridgeError(reason))

    # --- the ROS thread ---

    def _spin(self) -> None:
        assert self._executor is not None and self._context is not None
        try:
            while self._context.ok() and not self._stopping.is_set():
                self._executor.spin_once(timeout_sec=SPIN_PERIOD_S)
                # The guard's callback drains the queue; this drains what a lost or deferred wake
                # left (a call must never wait for the next unrelated wake).
                self._drain_pending_calls()
            if not self._stopping.is_set():
                self._failure = "the rclpy context was shut down"
        except ExternalShutdownException:
            if not self._stopping.is_set():
                self._failure = "the rclpy context was shut down"
        except Exception as error:  # noqa: BLE001 - kept in `failure` and the log; the thread ends
            if not self._stopping.is_set():
                self._failure = f"{type(error).__name__}: {error}"
                logger.exception("the ROS executor thread failed")
        finally:
            self._close()
            self._tear_down()

    def _tear_down(self) -> None:
        """Destroy executor, owned entities and node, then the context: on the ROS thread only."""
        assert self._executor is not None and self._node is not None and self._context is not None
        try:
            self._executor.shutdown(timeout_sec=0.5)
            for entity in self._owned:
                entity.destroy()
            self._owned.clear()
            self._node.destroy_node()
        except Exception:  # noqa: BLE001 - shutting down; nothing left to report to
            logger.debug("node teardown raised", exc_info=True)
        try:
            self._context.try_shutdown()
            self._context.destroy()
        except Exception:  # noqa: BLE001
            logger.debug("context shutdown raised", exc_info=True)


def _tell_end(listener: Callable[[str], None], reason: str) -> None:
    try:
        listener(reason)
    except Exception:  # noqa: BLE001 - the others must be told too
        logger.exception("a listener of the ROS thread's end failed")


def _run_into(call: Callable[[], T], result: concurrent.futures.Future[T]) -> None:
    try:
        value = call()
    except BaseException as error:  # noqa: BLE001 - handed to the waiting thread
        result.set_exception(error)
    else:
        result.set_result(value)
