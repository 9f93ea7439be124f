"""Task sequencer: GetLabware and PutLabware as sequences of the robot's own actions.

    python -m tiago_sim.sequencer [--world FILE] [--params tiago_sim/sequencer/sequencer.yaml]

A separate node and only a client of the robot-level actions (/navigate_to_poi, /undock,
/play_motion, /marker_motion, /gripper) and of /describe_workcell, /robot_state and
/station_states, so it runs unchanged against a real robot offering the same interfaces.

Threads: ONE thread spins a SingleThreadedExecutor; execute callbacks are coroutines that await
sub-goals, so every rclpy object is used on that thread only. Feedback aggregates the running
sub-action's progress over the plan (estimated durations) and goes out at `feedback_hz`.
Cancel cancels the running sub-action; the plate is then left where that step left it (nest,
hotel or gripper, as /robot_state reports). An abort carries the sub-action's code and message.
"""

from __future__ import annotations

import argparse
import logging
import time
from pathlib import Path
from typing import Any

import yaml
from action_msgs.msg import GoalStatus
from labware_interfaces.action import (
    GetLabware,
    Gripper,
    MarkerMotion,
    NavigateToPoi,
    PlayMotion,
    PutLabware,
    Undock,
)
from labware_interfaces.msg import ErrorCodes, RobotState, StationStates
from labware_interfaces.srv import DescribeWorkcell
from rclpy.action import ActionClient, ActionServer, CancelResponse, GoalResponse
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.task import Future

from labware_model.workcell import StationDescription, WorkcellDescription
from tiago_sim.node_main import spin_node
from tiago_sim.sequencer.plans import (
    STATE_REFUSALS,
    Step,
    TaskRefused,
    get_plan,
    put_plan,
    retreat_after_empty_grasp,
)

log = logging.getLogger("tiago_sim.sequencer")

DEFAULT_PARAMS = Path(__file__).with_name("sequencer.yaml")
SUB_ACTIONS = {
    "undock": (Undock, "/undock"),
    "navigate": (NavigateToPoi, "/navigate_to_poi"),
    "play_motion": (PlayMotion, "/play_motion"),
    "gripper": (Gripper, "/gripper"),
    "marker_motion": (MarkerMotion, "/marker_motion"),
}


class StepFailed(Exception):
    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message


class TaskRun:
    """Progress bookkeeping of one task goal (lives on the executor thread)."""

    def __init__(
        self, goal_handle: Any, feedback_type: type, plan: list[Step], estimates: dict[str, float]
    ) -> None:
        self.goal_handle = goal_handle
        self.feedback_type = feedback_type
        self.durations = [max(estimates.get(step.action, 3.0), 0.1) for step in plan]
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


class Sequencer:
    """The node's behaviour: two task action servers over the robot's action clients."""

    def __init__(self, node: Node, params: dict[str, Any]) -> None:
        self.node = node
        for name in ("arm", "feedback_hz", "server_wait_s", "step_timeout_s", "state_max_age_s"):
            node.declare_parameter(name, params[name])
        for action, seconds in params["estimates_s"].items():
            node.declare_parameter(f"estimates_s.{action}", float(seconds))
        self.clients = {name: ActionClient(node, kind, topic) for name, (kind, topic) in SUB_ACTIONS.items()}
        self.describe_client = node.create_client(DescribeWorkcell, "/describe_workcell")
        self.workcell: WorkcellDescription | None = None
        self.robot_state: RobotState | None = None
        self.station_states: StationStates | None = None
        self.state_times: dict[str, float] = {}
        qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        node.create_subscription(RobotState, "/robot_state", self._on_robot_state, qos)
        node.create_subscription(StationStates, "/station_states", self._on_station_states, qos)
        self.active: TaskRun | None = None
        for kind, topic, plan in (
            (GetLabware, "/get_labware", get_plan),
            (PutLabware, "/put_labware", put_plan),
        ):
            ActionServer(
                node,
                kind,
                topic,
                self._execute(kind, plan),
                goal_callback=lambda _goal: GoalResponse.ACCEPT,
                cancel_callback=self._on_cancel,
            )
        self.feedback_timer = node.create_timer(
            1.0 / max(float(params["feedback_hz"]), 2.0), self._feedback_tick
        )

    def param(self, name: str) -> Any:
        return self.node.get_parameter(name).value

    def _on_robot_state(self, message: RobotState) -> None:
        self.robot_state = message
        self.state_times["robot"] = time.monotonic()

    def _on_station_states(self, message: StationStates) -> None:
        self.station_states = message
        self.state_times["stations"] = time.monotonic()

    def _feedback_tick(self) -> None:
        if self.active is not None:
            self.active.publish()

    def _on_cancel(self, _goal_handle: Any) -> CancelResponse:
        run = self.active
        if run is not None and run.sub_goal is not None:
            run.sub_goal.cancel_goal_async()
        return CancelResponse.ACCEPT

    async def _sleep(self, seconds: float) -> None:
        """Wait without blocking the executor (a one-shot timer completes a future)."""
        done = Future()

        def fire() -> None:
            timer.cancel()
            done.set_result(True)

        timer = self.node.create_timer(seconds, fire)
        await done
        self.node.destroy_timer(timer)

    async def _wait_ready(self, what: str, is_ready: Any) -> None:
        deadline = time.monotonic() + float(self.param("server_wait_s"))
        while not is_ready():
            if time.monotonic() > deadline:
                raise StepFailed(ErrorCodes.INTERNAL, f"robot not available: {what} does not answer")
            await self._sleep(0.1)

    async def _describe(self) -> WorkcellDescription:
        if self.workcell is None:
            await self._wait_ready("/describe_workcell", self.describe_client.service_is_ready)
            response = await self.describe_client.call_async(DescribeWorkcell.Request())
            self.workcell = WorkcellDescription(
                stations=tuple(
                    StationDescription(s.name, int(s.sub_positions), s.poi) for s in response.stations
                ),
                hotel_slots=int(response.hotel_slots),
                pois=tuple(response.pois),
                dock_poi=response.dock_poi,
            )
        return self.workcell

    def _fresh_states(self) -> tuple[RobotState, StationStates]:
        max_age = float(self.param("state_max_age_s"))  # waited for in _wait_states
        now = time.monotonic()
        for key, what in (("robot", "/robot_state"), ("stations", "/station_states")):
            if now - self.state_times.get(key, -1e9) > max_age:
                raise StepFailed(ErrorCodes.INTERNAL, f"no recent {what}: is the robot running?")
        assert self.robot_state is not None and self.station_states is not None
        return self.robot_state, self.station_states

    async def _plan(self, request: Any, make_plan: Any, arrived: float) -> list[Step]:
        """The goal's steps, or TaskRefused. A refusal read from the state topics (slot or nest full
        or empty) must also hold in states received after the goal arrived: a plate placed just
        before the goal can be missing from an older message."""
        workcell = await self._describe()
        await self._wait_ready("/robot_state and /station_states", lambda: len(self.state_times) == 2)

        def plan() -> list[Step]:
            robot_state, station_states = self._fresh_states()
            return make_plan(request, workcell, robot_state, station_states, str(self.param("arm")))

        try:
            return plan()
        except TaskRefused as refusal:
            if refusal.code not in STATE_REFUSALS or min(self.state_times.values()) > arrived:
                raise
            log.info("%s read from states older than the goal: reading fresh ones", refusal.code)
        await self._wait_ready(
            "/robot_state and /station_states", lambda: min(self.state_times.values()) > arrived
        )
        return plan()

    def _execute(self, kind: Any, make_plan: Any) -> Any:
        async def execute(goal_handle: Any) -> Any:
            result = kind.Result()
            result.labware_id = goal_handle.request.labware_id
            if self.active is not None:
                return self._finish(goal_handle, result, ErrorCodes.BUSY, "busy with another transfer")
            try:
                plan = await self._plan(goal_handle.request, make_plan, arrived=time.monotonic())
            except (TaskRefused, StepFailed) as refusal:
                return self._finish(goal_handle, result, refusal.code, refusal.message)
            result.labware_id = self._labware_id(goal_handle.request, kind is PutLabware)
            estimates = {a: float(self.param(f"estimates_s.{a}")) for a in SUB_ACTIONS}
            run = TaskRun(goal_handle, kind.Feedback, plan, estimates)
            self.active = run
            try:
                run.publish()
                for index, step in enumerate(plan):
                    run.index, run.step_progress, run.step_remaining_s, run.phase = (
                        index,
                        0.0,
                        None,
                        step.phase,
                    )
                    if goal_handle.is_cancel_requested:
                        raise StepFailed(ErrorCodes.CANCELED, f"canceled before {step.describe()}")
                    run.publish()  # a new phase is news: clients see it at once, not at the next tick
                    await self._run_step(run, step)
                run.index, run.phase = len(plan), "done"
                run.publish()  # the last word is progress 1.0
                return self._finish(goal_handle, result, "", "done")
            except StepFailed as failure:
                if failure.code == ErrorCodes.GRASP_FAILED:
                    await self._retreat(run, plan)
                return self._finish(goal_handle, result, failure.code, failure.message)
            except Exception as error:  # noqa: BLE001 - every goal ends with a result
                log.exception("task failed")
                return self._finish(goal_handle, result, ErrorCodes.INTERNAL, f"internal error: {error}")
            finally:
                self.active = None

        return execute

    async def _retreat(self, run: TaskRun, plan: list[Step]) -> None:
        """Best effort after an empty grasp: bring the arm out of the nest or pocket and tuck it;
        the task still ends with GRASP_FAILED, whatever happens here."""
        for step in retreat_after_empty_grasp(plan, run.index):
            try:
                run.phase = step.phase
                await self._run_step(run, step)
            except StepFailed as failure:
                log.warning("retreat after an empty grasp stopped: %s", failure.message)
                return

    def _labware_id(self, request: Any, from_hotel: bool) -> str:
        """The plate's id as the robot's sensors report it at the source, else the one asked for."""
        if from_hotel and self.robot_state is not None:
            for slot in self.robot_state.hotel:
                if slot.index == request.internal_position and slot.labware_id:
                    return slot.labware_id
        if not from_hotel and self.station_states is not None:
            for nest in self.station_states.nests:
                same = nest.station == request.handover_position and nest.sub_position == request.sub_position
                if same and nest.labware_id:
                    return nest.labware_id
        return request.labware_id

    async def _run_step(self, run: TaskRun, step: Step) -> None:
        kind, _topic = SUB_ACTIONS[step.action]
        client = self.clients[step.action]
        await self._wait_ready(SUB_ACTIONS[step.action][1], client.server_is_ready)
        goal = kind.Goal()
        for field_name, value in step.goal.items():
            setattr(goal, field_name, value)

        def on_feedback(message: Any) -> None:
            run.step_progress = float(message.feedback.progress)
            run.step_remaining_s = float(message.feedback.remaining_time_s)
            if message.feedback.phase:
                run.phase = f"{step.phase}: {message.feedback.phase}"

        log.info("step %d: %s", run.index + 1, step.describe())
        sub_goal = await client.send_goal_async(goal, feedback_callback=on_feedback)
        if not sub_goal.accepted:
            raise StepFailed(ErrorCodes.INTERNAL, f"{step.describe()}: goal rejected")
        run.sub_goal = sub_goal
        if run.goal_handle.is_cancel_requested:
            sub_goal.cancel_goal_async()
        response = await sub_goal.get_result_async()
        run.sub_goal = None
        sub_result = response.result
        if response.status == GoalStatus.STATUS_CANCELED or sub_result.error_code == ErrorCodes.CANCELED:
            raise StepFailed(ErrorCodes.CANCELED, f"canceled during {step.describe()}: {sub_result.message}")
        if not sub_result.success:
            raise StepFailed(
                sub_result.error_code or ErrorCodes.INTERNAL, f"{step.describe()}: {sub_result.message}"
            )
        if step.expect_holding and not sub_result.holding:
            raise StepFailed(ErrorCodes.GRASP_FAILED, f"{step.describe()}: nothing between the fingers")
        run.step_progress, run.step_remaining_s = 1.0, 0.0

    @staticmethod
    def _finish(goal_handle: Any, result: Any, code: str, message: str) -> Any:
        result.success = not code
        result.error_code = code
        result.message = message
        if not code:
            goal_handle.succeed()
        elif code == ErrorCodes.CANCELED and goal_handle.is_cancel_requested:
            goal_handle.canceled()
        else:
            goal_handle.abort()
        log.info("task ended: %s %s", code or "OK", message)
        return result


def load_params(path: Path) -> dict[str, Any]:
    params = yaml.safe_load(Path(path).read_text())
    missing = {
        "arm",
        "feedback_hz",
        "server_wait_s",
        "step_timeout_s",
        "state_max_age_s",
        "estimates_s",
    } - set(params)
    if missing:
        raise ValueError(f"{path}: missing {', '.join(sorted(missing))}")
    return params


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tiago_sim.sequencer", description=__doc__.split("\n")[0])
    parser.add_argument(
        "--world", type=Path, default=None, help="accepted for symmetry; the robot describes the cell"
    )
    parser.add_argument(
        "--params", type=Path, default=DEFAULT_PARAMS, help="parameter YAML (default: %(default)s)"
    )
    parser.add_argument("--log-level", default="INFO")
    args = parser.parse_args(argv)
    logging.basicConfig(level=args.log_level, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    params = load_params(args.params)

    def build(node: Node) -> Sequencer:
        sequencer = Sequencer(node, params)
        log.info("sequencer ready")
        return sequencer

    return spin_node("labware_sequencer", SingleThreadedExecutor, build)
