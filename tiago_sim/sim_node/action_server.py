"""How the simulator's stand-ins for the robot's action servers are made: goals accepted unless a
check rejects them, every cancel accepted (the stand-in then stops what the goal started),
callbacks free to run in parallel.

Why one place: the controllers, navigation, docking and play_motion2 stand-ins all serve a vendor's
action the way its own server does, which accepts a cancel at any time.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import CallbackGroup, ReentrantCallbackGroup
from rclpy.node import Node


def cancellable_server(
    node: Node,
    action_type: Any,
    name: str,
    execute: Callable[[Any], Any],
    group: CallbackGroup | None = None,
    check: Callable[[Any], GoalResponse] | None = None,
) -> ActionServer:
    """An action server on `node` whose goals run `execute(handle)` and whose cancels are accepted;
    `check(goal)` may reject a goal first (else every goal is accepted)."""
    return ActionServer(
        node,
        action_type,
        name,
        execute_callback=execute,
        goal_callback=check or (lambda _goal: GoalResponse.ACCEPT),
        cancel_callback=lambda _handle: CancelResponse.ACCEPT,
        callback_group=group or ReentrantCallbackGroup(),
    )
