"""A node in its own rclpy context, spun by a multi-threaded executor on another thread, as the
robot side spins its nodes: for tests of races between a caller's thread and executor threads.
What ended the executor's spin, if anything did, is kept for the test to assert on."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager

import rclpy
from rclpy.context import Context
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node


@contextmanager
def spun_node(name: str, threads: int = 3) -> Iterator[tuple[Node, list[BaseException]]]:
    """The node, and the list that receives the exception that ended the spin (empty while it runs).
    Parts created on the node before the block ends are torn down with it."""
    context = Context()
    rclpy.init(context=context)
    node = rclpy.create_node(name, context=context)
    executor = MultiThreadedExecutor(num_threads=threads, context=context)
    executor.add_node(node)
    ended: list[BaseException] = []

    def spin() -> None:
        try:
            executor.spin()
        except BaseException as error:  # noqa: BLE001 - what ended the executor is the finding
            ended.append(error)

    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    try:
        yield node, ended
    finally:
        executor.shutdown()
        spinner.join(timeout=10.0)
        for part in list(node.waitables):  # action servers and clients, once nothing spins them
            if hasattr(part, "destroy"):
                part.destroy()
        node.destroy_node()
        rclpy.shutdown(context=context)
