"""One task goal's run: its progress over the plan's steps, and the failure of a step.

Why apart from the node: the bookkeeping of progress and remaining time is plain arithmetic over
the plan's estimated durations, testable without ROS. Lives on the sequencer's executor thread
(`publish` sends the goal's feedback).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from labware_model.progress import MonotonicProgress
from tiago_sim.sequencer.plans import Step
from tiago_sim.sequencer.step_durations import StepDurations


class StepFailed(Exception):
    """A step, or a wait of the task, failed: `code` is an ErrorCodes value, `message` says why."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message


class TaskRun:
    """Progress bookkeeping of one task goal (lives on the executor thread)."""

    def __init__(
        self,
        goal_handle: Any,
        feedback_type: type,
        plan: list[Step],
        durations: list[float],
        task: str = "",
        measured: list[bool] | None = None,
        clock: Callable[[], float] | None = None,
    ) -> None:
        self.goal_handle = goal_handle
        self.task = task  # "GetLabware" or "PutLabware": step kinds are counted per task
        self.feedback_type = feedback_type
        self.durations = durations  # estimated robot seconds per step (step_durations)
        # per step: its duration was measured (a kind the table names or that ran), so its remaining
        # time is that duration less the robot time since it began (`clock`, robot seconds)
        self.measured = measured or [False] * len(durations)
        self.clock = clock
        self.step_started = 0.0
        self.total = sum(self.durations)
        self.index = 0
        self.step_progress = 0.0
        self.step_remaining_s: float | None = None
        self.phase = "starting"
        self.sub_goal: Any = None  # ClientGoalHandle of the running sub-action
        self.reported = MonotonicProgress()  # what clients are sent: a step running long never pulls it back

    @classmethod
    def for_plan(
        cls, goal_handle: Any, kind: type, plan: list[Step], known: StepDurations, clock: Callable[[], float]
    ) -> TaskRun:
        """The run of a task action `kind` (GetLabware, PutLabware) over `plan`, estimated by `known`."""
        task = kind.__name__
        durations = [known.estimate(step, task) for step in plan]
        measured = [known.measured(step, task) for step in plan]
        return cls(goal_handle, kind.Feedback, plan, durations, task, measured, clock)

    @property
    def index(self) -> int:
        """The running step (len(plan) once done); setting it starts that step's clock."""
        return self._index

    @index.setter
    def index(self, value: int) -> None:
        self._index = value
        self.step_started = self.clock() if self.clock is not None else 0.0

    def follow_sub_goal(self, step_phase: str) -> tuple[Callable[[Any], None], Callable[[], None]]:
        """The feedback callback of one step's sub-goal, and the switch that silences it once its
        result is in: feedback and result travel apart, and a late message must not move the next step."""
        live = [True]

        def on_feedback(message: Any) -> None:
            if not live[0]:
                return
            self.step_progress = float(message.feedback.progress)
            self.step_remaining_s = float(message.feedback.remaining_time_s)
            if message.feedback.phase:
                self.phase = f"{step_phase}: {message.feedback.phase}"

        return on_feedback, lambda: live.__setitem__(0, False)

    def progress(self) -> float:
        done = sum(self.durations[: self.index])
        current = self.durations[self.index] * self.step_progress if self.index < len(self.durations) else 0.0
        return min((done + current) / self.total, 1.0) if self.total else 1.0

    def remaining_s(self) -> float:
        later = sum(self.durations[self.index + 1 :])
        if self.index >= len(self.durations):
            return 0.0
        if self.measured[self.index] and self.clock is not None:
            # Why not the sub-goal's own estimate: a motion's stages are estimated from path length
            # and speed limits, and came out 2 s short of a 3.3 s move to the hotel (-21 to -41 % at
            # half a GetLabware at pace 1); the measured duration of the step kind was 0.1 s off.
            return max(self.durations[self.index] - (self.clock() - self.step_started), 0.0) + later
        current = self.step_remaining_s
        if current is None:
            current = self.durations[self.index] * (1.0 - self.step_progress)
        return current + later

    def publish(self) -> None:
        feedback = self.feedback_type()
        feedback.progress = float(self.reported.advance(self.progress()))
        feedback.phase = self.phase
        feedback.remaining_time_s = float(self.remaining_s())
        self.goal_handle.publish_feedback(feedback)
