"""`/reset_lab` (std_srvs/Trigger): the lab back to its world file, without restarting a process.

Why in place: a downstream CI resets between tests, and restarting the robot side costs seconds
of start-up and DDS discovery each time. The sim thread builds its Simulation anew from the same
factory (so plates, robot pose and the drawn disturbances are exactly those of the start), and the
node's own memory of the old world (faults, a held grasp, the last marker sighting, a standing
error) is cleared through the hooks registered here.

Refused while a goal runs: the reset takes the action servers' motion slot, so no goal can start
during it either. Lives on: an executor thread (the service callback), work on the sim thread.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import Any

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import UInt32
from std_srvs.srv import Trigger

from tiago_sim.sim_node.sim_thread import SimThread
from tiago_skills.goal_run import ActionAbort, MotionSlot

log = logging.getLogger(__name__)

RESET_SERVICE = "/reset_lab"
RESETS_TOPIC = "/lab_resets"
"""std_msgs/UInt32, latched: how many resets the lab has had (listeners drop what they remembered)."""


class LabReset:
    """The reset service; `hooks` run after the rebuild, on the service's thread."""

    def __init__(self, node: Node, sim_thread: SimThread, slot: MotionSlot) -> None:
        self.sim_thread = sim_thread
        self.slot = slot
        self.hooks: list[Callable[[], None]] = []
        self.count = 0
        latched = QoSProfile(
            depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
        )
        self.resets_pub = node.create_publisher(UInt32, RESETS_TOPIC, latched)
        self.resets_pub.publish(UInt32(data=0))
        node.create_service(Trigger, RESET_SERVICE, self._serve)

    def _serve(self, _request: Any, response: Any) -> Any:
        response.success, response.message = self.reset()
        return response

    def reset(self) -> tuple[bool, str]:
        """(done, what happened); not done while the robot is busy with a goal."""
        try:
            self.slot.acquire("lab reset")
        except ActionAbort as busy:
            return False, f"the robot is busy ({busy.message}): cancel or wait for it first"
        started = time.monotonic()
        try:
            sim_time = self.sim_thread.rebuild()
            for hook in self.hooks:
                hook()
        except Exception as error:  # noqa: BLE001 - the caller reads why
            log.exception("lab reset failed")
            return False, f"lab reset failed: {error}"
        finally:
            self.slot.release()
        self.count += 1
        self.resets_pub.publish(UInt32(data=self.count))
        took = time.monotonic() - started
        log.info(
            "lab reset to its world file in %.2f s (reset %d, sim time %.1f s)", took, self.count, sim_time
        )
        return True, f"lab reset to its world file in {took:.2f} s"
