"""Exceptions of the bridge: callers above (SiLA handlers) turn these into SiLA errors."""

from __future__ import annotations


class BridgeError(RuntimeError):
    """Something in the ROS bridge went wrong; the message says what."""


class BridgeTimeout(BridgeError):
    """A wait on the ROS side (server, goal, result, service) took longer than allowed."""


class ServerUnavailable(BridgeError):
    """An action server or service did not appear within the wait time."""


class GoalRejected(BridgeError):
    """The action server rejected the goal (for instance, it is busy)."""


class GoalAbandoned(BridgeError):
    """This side stopped waiting for a goal because the robot side is gone and will not answer
    (`ActionGoal.abort`, used by the deployment's supervisor). Nothing was sent to the robot."""
