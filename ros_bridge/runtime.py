"""One rclpy context, one node and one executor, spun on one thread.

Threads: `RosRuntime.start()` creates a private rclpy context, a node and a single-threaded
executor, and starts ONE daemon thread (the "ROS thread") that spins the executor. Every
rclpy object (clients, subscriptions, goal handles) is created and used on that thread only:
other threads (SiLA handler threads, the CLI's main thread) hand work over with `submit()`,
which returns a `concurrent.futures.Future`, and wait on that future with a timeout. No thread
other than the ROS thread ever spins.

rclpy's own action client is not safe to call from a second thread while the executor spins
(it registers the pending goal after sending the request), hence the hand-over queue: a guard
condition wakes the executor, whose callback drains the queue on the ROS thread.
"""

from __future__ import annotations

import concurrent.futures
import logging
import queue
import threading
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
        self._wake = None
        self._stopping = threading.Event()
        self._owned: list[Any] = []  # entities the node does not destroy itself (action clients)

    @property
    def node(self) -> Node:
        """The bridge node. Use it only on the ROS thread (inside `submit`)."""
        if self._node is None:
            raise BridgeError("the ROS runtime is not started")
        return self._node

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive() and not self._stopping.is_set()

    def own(self, entity: T) -> T:
        """Destroy `entity` (anything with `destroy()`) with the node: rclpy's destroy_node skips
        action clients, and one left alive keeps the node's DDS participant alive with it."""
        self._owned.append(entity)
        return entity

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
        """Stop the ROS thread, destroy the node, then shut the context down. Safe to call twice.

        Order matters: the node is destroyed while its context is still valid, so its DDS entities
        and participant go at once (destroyed after shutdown they linger until garbage collection,
        and a process that starts runtime after runtime, like the bench, piles up participants)."""
        if self._thread is None or self._stopping.is_set():
            return
        self._stopping.set()
        assert self._context is not None and self._executor is not None and self._node is not None
        self._thread.join(timeout_s)  # the spin loop checks the flag every 0.1 s
        if self._thread.is_alive():
            logger.warning("the ROS thread did not stop within %.1f s", timeout_s)
        self._fail_pending_calls()
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
        logger.info("ROS runtime %s stopped", self._node_name)

    def __enter__(self) -> RosRuntime:
        return self.start()

    def __exit__(self, *exc_info: object) -> None:
        self.stop()

    def submit(self, call: Callable[[], T]) -> concurrent.futures.Future[T]:
        """Run `call` on the ROS thread; its return value (or exception) lands in the future."""
        result: concurrent.futures.Future[T] = concurrent.futures.Future()
        if not self.running:
            result.set_exception(BridgeError("the ROS runtime is not running"))
            return result
        if self.on_ros_thread():
            _run_into(call, result)
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
                    f"the ROS thread did not answer within {timeout_s:.1f} s (the call was withdrawn)"
                ) from error
        try:  # it started just now: let it finish rather than leave its effect unknown
            return future.result(timeout=timeout_s)
        except concurrent.futures.TimeoutError as error:
            waited = 2 * timeout_s
            raise BridgeTimeout(f"the ROS thread did not finish a call within {waited:.1f} s") from error

    def _drain_pending_calls(self) -> None:
        while True:
            try:
                call, result = self._pending_calls.get_nowait()
            except queue.Empty:
                return
            if result.set_running_or_notify_cancel():
                _run_into(call, result)

    def _fail_pending_calls(self) -> None:
        while True:
            try:
                _call, result = self._pending_calls.get_nowait()
            except queue.Empty:
                return
            if not result.done():
                result.set_exception(BridgeError("the ROS runtime stopped"))

    def _spin(self) -> None:
        assert self._executor is not None and self._context is not None
        try:
            while self._context.ok() and not self._stopping.is_set():
                self._executor.spin_once(timeout_sec=0.1)
        except ExternalShutdownException:
            pass
        except Exception:  # noqa: BLE001 - keep the reason in the log, the thread ends either way
            if not self._stopping.is_set():
                logger.exception("the ROS executor thread failed")


def _run_into(call: Callable[[], T], result: concurrent.futures.Future[T]) -> None:
    try:
        value = call()
    except BaseException as error:  # noqa: BLE001 - handed to the waiting thread
        result.set_exception(error)
    else:
        result.set_result(value)
