"""The main loop every robot-side process shares: one rclpy node spun until SIGINT or SIGTERM.

Why: the sim node and the sequencer start, spin and stop the same way (signals set a flag so a
stopped node exits quietly instead of raising ExternalShutdownException mid-callback); one copy
keeps their shutdown order alike. A node also stops once the process that started it is gone (it
was re-parented): a deployment killed without its clean-up (SIGKILL, or SIGTERM to a script that
does not handle it) left its robot side running, still in its ROS domain, and the next run that
reserved that domain met two robots answering one action. Lives on: the process's main thread.
"""

from __future__ import annotations

import faulthandler
import logging
import os
import signal
from collections.abc import Callable
from typing import Any

import rclpy
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from tiago_sim.started_by import starter_pid

log = logging.getLogger(__name__)


def stacks_on_sigusr1() -> None:
    """Write every thread's stack to stderr (the process's log) on SIGUSR1: a deployment whose robot
    side does not come up asks for them (ProcessGroup.stacks). Called first in a process's main."""
    faulthandler.register(signal.SIGUSR1, all_threads=True)


def spin_node(
    node_name: str,
    make_executor: Callable[[], Executor],
    build: Callable[[Node], Any],
    *,
    before_shutdown: Callable[[], None] | None = None,
) -> int:
    """Create ``node_name``, ``build(node)`` its parts, spin until a signal, then tear down.

    ``make_executor`` is called after rclpy.init (an executor needs the initialised context);
    ``build`` may return the object that owns the node's callbacks (kept alive while spinning);
    ``before_shutdown`` runs first on the way out (e.g. stopping a worker thread).
    """
    rclpy.init(args=None, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node(node_name)
    executor = make_executor()
    stopping = False

    def request_stop(signum: int, _frame: Any) -> None:
        nonlocal stopping
        log.info("signal %d: shutting down", signum)
        stopping = True

    signal.signal(signal.SIGINT, request_stop)
    signal.signal(signal.SIGTERM, request_stop)
    parent = starter_pid()
    owner = None
    try:
        owner = build(node)
        executor.add_node(node)
        while not stopping and rclpy.ok():
            executor.spin_once(timeout_sec=0.1)
            if os.getppid() != parent:
                log.warning("the process that started this node (pid %d) is gone: shutting down", parent)
                break
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if before_shutdown is not None:
            before_shutdown()
        executor.shutdown(timeout_sec=1.0)
        node.destroy_node()
        if rclpy.ok():
            rclpy.shutdown()
        del owner
    return 0
