"""Running the robot's goals one at a time: send, wait within bounds, cancel, abort, see the effect.

Why apart from the controller: this is the part of the robot's logic that talks to its back end
about a goal in flight (the active goal and the cancel token of the command that sent it), with
every wait bounded by `ControllerWaits` or the step timeout. The controller decides which goal a
command needs; this runs it and turns every kind of back-end trouble into a failed outcome, so
that the controller always settles the inventory and raises its own defined error.

Threads: `run` blocks the calling SiLA handler thread; `stop`, `cancel` and `abort` may come from
any other thread while it waits (one lock guards the active goal).
"""

from __future__ import annotations

import dataclasses
import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass

from ros_bridge.errors import BridgeError, BridgeTimeout
from ros_bridge.goal_status import ActionGoal, ActionOutcome
from ros_bridge.progress import CommandProgress
from ros_bridge.workcell import RobotStatus
from sila_labware.device.cancellation import CancelToken, current_token
from sila_labware.device.robot_backend import RobotBackend

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class ControllerWaits:
    """How long (s) the controller waits on the back end besides a step's own run time."""

    accept_s: float = 30.0
    """For the robot side to accept a goal."""
    cancel_s: float = 10.0
    """For a goal cancelled after its step timed out to end."""
    state_report_s: float = 2.0
    """For the robot state to show a motion's effect (/robot_state lags action results)."""
    settle_s: float = 3.0
    """For the robot state and a nest sensor to show a transfer's outcome (/station_states
    comes at 2 Hz, /robot_state on change)."""


class GoalRunner:
    """The robot's goal in flight, and what waits on it (see the module docstring)."""

    def __init__(self, link: RobotBackend, step_timeout_s: float, waits: ControllerWaits) -> None:
        self._link = link
        self.step_timeout_s = step_timeout_s
        self.waits = waits
        self._active_goal: ActionGoal | None = None
        self._active_token: CancelToken | None = None  # the cancel token of the command that sent it
        self._active_lock = threading.Lock()

    def stop(self) -> bool:
        """Cancel whatever goal runs and return once the robot stands (bounded: `waits.cancel_s`
        for the goal, and again for the state), so that every state property already says so; True
        if a goal was running."""
        with self._active_lock:
            goal = self._active_goal
        if goal is None or goal.done:
            return False
        goal.cancel()
        self._await_standing(goal)
        return True

    def cancel(self, token: CancelToken, reason: str) -> bool:
        """Cancel the command running under `token` (see `cancellation`): its running goal now, and
        any goal it would send next. True if one of its goals was running."""
        token.cancel(reason)
        with self._active_lock:
            goal = self._active_goal if self._active_token is token else None
        if goal is None or goal.done:
            return False
        goal.cancel()
        self._await_standing(goal)
        return True

    def abort(self, reason: str) -> bool:
        """End the waiting command now (the robot side is gone and will not answer): its goal ends
        with GoalAbandoned(`reason`); True if a goal was still running. The command then settles
        the inventory and raises its defined error as for any failed goal. Any thread."""
        with self._active_lock:
            goal = self._active_goal
        return goal is not None and goal.abort(reason)

    def _await_standing(self, goal: ActionGoal) -> None:
        """After a cancel: the goal has ended and the robot state shows it at rest."""
        try:
            goal.wait(self.waits.cancel_s)
        except BridgeError:
            logger.warning("%s: no end within %.0f s of the cancel", goal.action_name, self.waits.cancel_s)
        # Bounded by cancel_s, not state_report_s: a braking base reports its stand only once it
        # stands, which on a busy machine at a real-time pace can take longer than 2 s of wall time.
        self.await_state(lambda status: status.at_rest, "the robot at rest", within_s=self.waits.cancel_s)

    def await_state(
        self,
        shows: Callable[[RobotStatus], bool],
        what: str,
        progress: CommandProgress | None = None,
        within_s: float | None = None,
    ) -> None:
        """After a base motion succeeded, wait until /robot_state shows its effect, so that the
        command ends with the state properties (and the next command's checks) already true: the
        state topic lags action results. The command's `progress` then says what remains: at most
        this wait (a client counts a remaining time down, and the goal's last estimate has run
        out). Bounded by `within_s` (default `waits.state_report_s`)."""
        bound_s = self.waits.state_report_s if within_s is None else within_s
        if progress is not None:
            progress.report(progress.fraction, self.waits.state_report_s)
        try:
            self._link.wait_for_robot_status(shows, bound_s)
        except BridgeTimeout:
            logger.warning("the motion succeeded but the robot state does not report %s yet", what)

    def run(self, send: Callable[[], ActionGoal], what: str) -> ActionOutcome:
        """Send the goal and return its outcome; back-end trouble (no answer, rejection, timeout, an
        abandoned goal, even while sending) becomes a failed outcome whose error code names the
        bridge error, so that callers always settle the inventory and raise their own defined error.
        A command cancelled through its token sends no further goal."""
        token = current_token()
        if token is not None and token.cancelled:
            return ActionOutcome(False, "CANCELED", f"{token.reason}; {what} was not started", "CANCELED")
        try:
            goal = send()
        except BridgeError as error:
            return ActionOutcome(False, type(error).__name__, f"{what} could not be sent: {error}", "")
        with self._active_lock:
            self._active_goal, self._active_token = goal, token
        try:
            if token is not None and token.cancelled:  # cancelled while the goal was being sent
                goal.cancel()
            goal.wait_accepted(self.waits.accept_s)
            try:
                outcome = goal.result(self.step_timeout_s)
                if token is not None and token.cancelled and not outcome.success:
                    outcome = dataclasses.replace(outcome, message=f"{token.reason}; {outcome.message}")
                return outcome
            except BridgeTimeout:
                logger.warning("%s took longer than %.0f s: cancelling it", what, self.step_timeout_s)
                goal.cancel()
                try:
                    return goal.result(self.waits.cancel_s)
                except BridgeTimeout:
                    return ActionOutcome(
                        False, "TIMEOUT", f"{what}: no result within {self.step_timeout_s:.0f} s", ""
                    )
        except BridgeError as error:
            return ActionOutcome(False, type(error).__name__, str(error), "")
        finally:
            with self._active_lock:
                self._active_goal, self._active_token = None, None
