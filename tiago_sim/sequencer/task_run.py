"""One task goal's run: its progress over the plan's steps, and the failure of a step.

Why apart from the node: the bookkeeping of progress and remaining time is plain arithmetic over
the plan's estimated durations, testable without ROS. Lives on the sequencer's executor thread
(`publish` sends the goal's feedback).
"""

from __future__ import annotations

from typing import Any

from tiago_sim.sequencer.plans import Step


class StepFailed(Exception):
    """A step, or a wait of the task, failed: `code` is an ErrorCodes value, `message` says why."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message


class TaskRun:
    """Progress bookkeeping of one task goal (lives on the executor thread)."""

    def __init__(
        self, goal_handle: Any, feedback_type: type, plan: list[Step], durations: list[float], task: str = ""
    ) -> None:
        self.goal_handle = goal_handle
        self.task = task  # "GetLabware" or "PutLabware": step kinds are counted per task
        self.feedback_type = feedback_type
        self.durations = durations  # estimated robot seconds per step (step_durations)
        self.total = sum(self.durations)
        self.index = 0
        self.step_progress = 0.0
        self.step_remaining_s: float | None = None
        self.phase = "starting"
        self.sub_goal: Any = None  # ClientGoalHandle of the running sub-action

    def progress(self) -> float:
        done = sum(self.durations[: self.index])
        current = self.durations[self.index] * self.step_progress if self.index < len(self.durations) else 0.0
        return min((done + current) / self.total, 1.0) if self.total else 1.0

    def remaining_s(self) -> float:
        later = sum(self.durations[self.index + 1 :])
        if self.index >= len(self.durations):
            return 0.0
        current = self.step_remaining_s
        if current is None:
            current = self.durations[self.index] * (1.0 - self.step_progress)
        return current + later

    def publish(self) -> None:
        feedback = self.feedback_type()
        feedback.progress = float(self.progress())
        feedback.phase = self.phase
        feedback.remaining_time_s = float(self.remaining_s())
        self.goal_handle.publish_feedback(feedback)
