"""Break the bridge's ROS thread the way a bug in a callback would, through rclpy itself.

rclpy re-raises an exception from a callback (a subscription's, a timer's, a future's done
callback, a guard condition's) out of `spin_once`, which ends the thread that spins. Here a guard
condition whose callback raises is created and triggered on the ROS thread: nothing is patched,
and the runtime ends exactly as it did when an InvalidStateError escaped an rclpy done-callback.
"""

from __future__ import annotations

from ros_bridge.runtime import RosRuntime


class InjectedCallbackFailure(RuntimeError):
    """What the broken callback raises."""


def break_ros_thread(runtime: RosRuntime, message: str = "injected by the test") -> None:
    """Make the next spin of `runtime`'s ROS thread raise InjectedCallbackFailure(`message`)."""

    def fail() -> None:
        raise InjectedCallbackFailure(message)

    def arm() -> None:
        runtime.node.create_guard_condition(fail).trigger()

    runtime.call(arm)
