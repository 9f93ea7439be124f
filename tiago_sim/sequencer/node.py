"""Task sequencer: GetLabware and PutLabware as sequences of the robot's own actions.

    python -m tiago_sim.sequencer [--world FILE] [--params tiago_sim/sequencer/sequencer.yaml]
                                  [--inventory FILE] [--label-checks]     (see startup.py)

A separate node and only a client of the robot-level actions (/navigate_to_poi, /undock,
/play_motion, /marker_motion, /gripper) and of /describe_workcell, /robot_state and
/station_states, so it runs unchanged against a real robot offering the same interfaces.

Threads: ONE thread spins a SingleThreadedExecutor; execute callbacks are coroutines that await
sub-goals, so every rclpy object is used on that thread only. Feedback aggregates the running
sub-action's progress over the plan (estimated durations) and goes out at `feedback_hz`.
Cancel cancels the running sub-action; the plate is then left where that step left it (nest,
hotel or gripper, as /robot_state reports). An abort carries the sub-action's code and message.

A step is done when its sensors say so: after a step with a post-condition (plans.Expect), the
task waits at most `post_check_s` for a sensor report read after the step ended that shows the
plate where it must be; otherwise it fails with the step's code (PLATE_SLIPPED, PLACE_FAILED)
naming what the sensor saw, and after those (and GRASP_FAILED) the arm backs out empty and tucks
(plans.retreat_steps). Which sensors there are comes from /describe_workcell (`LabSensors`); a
lab without nest sensors is not read on /station_states at all: the head camera's look into the
nest (a /marker_motion "inspect" step) settles those checks with its result.

Every wait is bounded: a sub-goal that gives no result within `step_timeout_s` is cancelled and
the task aborts with NAVIGATION_FAILED (navigate, undock) or MOTION_FAILED, naming the step; a
sub-goal not accepted within `server_wait_s` and a cancel not answered within `cancel_wait_s`
abort with INTERNAL; /describe_workcell gets `describe_attempts` requests of `describe_timeout_s`
each, then the goal aborts with INTERNAL saying so.
"""

from __future__ import annotations

import logging
import time
from pathlib import Path
from typing import Any

from labware_interfaces.action import (
    GetLabware,
    PutLabware,
)
from labware_interfaces.msg import ErrorCodes, RobotState, StationStates
from labware_interfaces.srv import DescribeWorkcell
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.task import Future

from labware_model.holders import GRIPPER, Location, Nest
from labware_model.workcell import WorkcellDescription
from robot_port.action_client import ThreadSafeActionClient
from tiago_sim.sequencer.inventory_keeper import InventoryKeeper
from tiago_sim.sequencer.plans import (
    RETREAT_AFTER,
    STATE_REFUSALS,
    Step,
    TaskRefused,
    ends_of,
    get_plan,
    is_inspection,
    label_at_source,
    put_plan,
    retreat_steps,
)
from tiago_sim.sequencer.postconditions import topic_of, unmet
from tiago_sim.sequencer.step_durations import StepDurations, table_from_parameters
from tiago_sim.sequencer.sub_goals import SUB_ACTIONS, run_step
from tiago_sim.sequencer.task_run import StepFailed, TaskRun
from tiago_sim.sequencer.waits import describe_workcell, sleep, within

log = logging.getLogger("tiago_sim.sequencer")

PARAMETERS = tuple(  # every one in sequencer.yaml, besides estimates_s
    "arm feedback_hz server_wait_s step_timeout_s cancel_wait_s post_check_s describe_timeout_s "
    "describe_attempts state_max_age_s label_checks".split()
)
STATE_TOPICS = {"robot": "/robot_state", "stations": "/station_states"}


class Sequencer:
    """The node's behaviour: two task action servers over the robot's action clients."""

    def __init__(self, node: Node, params: dict[str, Any], inventory_file: Path | None = None) -> None:
        self.node = node
        for name in PARAMETERS:
            node.declare_parameter(name, params[name])
        self.estimate_keys = tuple(str(key) for key in params["estimates_s"])
        for key, seconds in params["estimates_s"].items():
            node.declare_parameter(f"estimates_s.{key}", float(seconds))
        self.clients = {
            name: ThreadSafeActionClient(node, kind, topic) for name, (kind, topic) in SUB_ACTIONS.items()
        }
        self.describe_client = node.create_client(DescribeWorkcell, "/describe_workcell")
        self.workcell: WorkcellDescription | None = None
        self.robot_state: RobotState | None = None
        self.station_states: StationStates | None = None
        self.state_times: dict[str, float] = {}
        self.idle_report_at = -1e9  # when the last /robot_state showing no goal running arrived
        self.report_arrived = Future()  # a post-condition check waits on it for the next state message
        qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        node.create_subscription(RobotState, "/robot_state", self._on_robot_state, qos)
        node.create_subscription(StationStates, "/station_states", self._on_station_states, qos)
        self.active: TaskRun | None = None
        self.inventory = InventoryKeeper(node, inventory_file)
        self.task_ended_at = -1e9  # the book follows the sensors only with reports read after it
        self.answering: set[str] = set()  # action servers known to answer (waits.wait_answering)
        self.step_durations = StepDurations({})  # robot seconds per step kind, learned as steps run
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
        self.camera_nests: dict[Nest, bool] = {}  # this task's looks into nests (no nest sensors)
        # Which sensors there are decides which reports the inventory follows: asked once the robot
        # reports (a task of the executor's own: a coroutine run as a subscription's callback is
        # not resumed once it awaits).
        self.described_at_start = False

    async def _describe_and_follow(self) -> None:
        try:
            workcell = await self._describe()
        except StepFailed as failure:
            log.warning("%s; asking again with the next robot state", failure.message)
            self.described_at_start = False
            return
        log.info("lab-added sensors read: %s", ", ".join(workcell.sensors.names()) or "none")
        self._follow_sensors()

    def _state_keys(self) -> tuple[str, ...]:
        """The state topics this lab's checks read: /station_states only where nests have sensors."""
        nests = self.workcell is None or self.workcell.sensors.nests
        return ("robot", "stations") if nests else ("robot",)

    def _book_at(self, holder: Location) -> str | None:
        record = self.inventory.book.at(holder)
        return None if record is None else record.labware_id

    def param(self, name: str) -> Any:
        return self.node.get_parameter(name).value

    def _on_robot_state(self, message: RobotState) -> None:
        self.robot_state = message
        if not self.described_at_start:
            self.described_at_start = True
            self.node.executor.create_task(self._describe_and_follow)
        self.state_times["robot"] = time.monotonic()
        if message.state not in (RobotState.STATE_MANIPULATING, RobotState.STATE_NAVIGATING):
            self.idle_report_at = self.state_times["robot"]
        self._report_in()
        self._follow_sensors()

    def _on_station_states(self, message: StationStates) -> None:
        self.station_states = message
        self.state_times["stations"] = time.monotonic()
        self._report_in()
        self._follow_sensors()

    def _follow_sensors(self) -> None:
        """Between transfers, the inventory follows the sensors (a plate taken away by hand, the lab
        reset): only with both reports received after the last transfer ended, which settled its
        plate itself from the reports its post-conditions read."""
        if self.active is not None or self.workcell is None or self.robot_state is None:
            return
        times = [self.state_times.get(key, -1e9) for key in self._state_keys()]
        if min(times) <= self.task_ended_at:
            return
        self.inventory.reconcile(self.robot_state, self._sensed_nests(), self.workcell.sensors)

    def _report_in(self) -> None:
        if not self.report_arrived.done():
            self.report_arrived.set_result(None)

    def _feedback_tick(self) -> None:
        if self.active is not None:
            self.active.publish()

    def _on_cancel(self, _goal_handle: Any) -> CancelResponse:
        run = self.active
        if run is not None and run.sub_goal is not None:
            run.sub_goal.cancel_goal_async()
        return CancelResponse.ACCEPT

    async def _wait_ready(self, what: str, is_ready: Any) -> None:
        deadline = time.monotonic() + float(self.param("server_wait_s"))
        while not is_ready():
            if time.monotonic() > deadline:
                raise StepFailed(ErrorCodes.INTERNAL, f"robot not available: {what} does not answer")
            await sleep(self.node, 0.1)

    async def _describe(self) -> WorkcellDescription:
        if self.workcell is None:
            await self._wait_ready("/describe_workcell", self.describe_client.service_is_ready)
            attempts, timeout_s = self.param("describe_attempts"), self.param("describe_timeout_s")
            self.workcell = await describe_workcell(self.node, self.describe_client, attempts, timeout_s)
        return self.workcell

    def _sensed_nests(self) -> StationStates | None:
        """/station_states where the lab's nests have sensors, else None (never read)."""
        return self.station_states if "stations" in self._state_keys() else None

    def _fresh_states(self) -> tuple[RobotState, StationStates | None]:
        max_age = float(self.param("state_max_age_s"))  # waited for in _wait_states
        now = time.monotonic()
        for key in self._state_keys():
            if now - self.state_times.get(key, -1e9) > max_age:
                raise StepFailed(ErrorCodes.INTERNAL, f"no recent {STATE_TOPICS[key]}: is the robot running?")
        assert self.robot_state is not None
        return self.robot_state, self._sensed_nests()

    def _states_since(self, moment: float) -> bool:
        return all(self.state_times.get(key, -1e9) > moment for key in self._state_keys())

    async def _plan(self, request: Any, make_plan: Any, arrived: float) -> list[Step]:
        """The goal's steps, or TaskRefused. A refusal read from the state topics (slot or nest full
        or empty) must also hold in states received after the goal arrived: a plate placed just
        before the goal can be missing from an older message."""
        workcell = await self._describe()
        topics = " and ".join(STATE_TOPICS[key] for key in self._state_keys())
        await self._wait_ready(topics, lambda: self._states_since(-1e9))

        def plan() -> list[Step]:
            robot_state, station_states = self._fresh_states()
            arm = str(self.param("arm"))
            return make_plan(request, workcell, robot_state, station_states, arm, self._book_at)

        try:
            return plan()
        except TaskRefused as refusal:
            if refusal.code not in STATE_REFUSALS or self._states_since(arrived):
                raise
            log.info("%s read from states older than the goal: reading fresh ones", refusal.code)
        await self._wait_ready(topics, lambda: self._states_since(arrived))
        return plan()

    def _execute(self, kind: Any, make_plan: Any) -> Any:
        async def execute(goal_handle: Any) -> Any:
            result = kind.Result()
            request = goal_handle.request
            result.labware_id = request.labware_id
            if self.active is not None:
                return self._finish(goal_handle, result, ErrorCodes.BUSY, "busy with another transfer")
            source, destination = ends_of(request, kind is PutLabware)
            try:
                plan = await self._plan(request, make_plan, arrived=time.monotonic())
                label = label_at_source(request, self.robot_state, self._sensed_nests(), kind is PutLabware)
                checks = bool(self.param("label_checks"))
                result.labware_id = self.inventory.name_for_goal(request, source, label, checks)
            except (TaskRefused, StepFailed) as refusal:
                return self._finish(goal_handle, result, refusal.code, refusal.message)
            self.step_durations.table = table_from_parameters(
                {key: float(self.param(f"estimates_s.{key}")) for key in self.estimate_keys}
            )
            run = TaskRun.for_plan(goal_handle, kind, plan, self.step_durations, self._robot_seconds)
            self.active = run
            self.camera_nests = {}
            touched = False  # a grasp of the plate was tried (until then it lies where it lay)
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
                    started = self._robot_seconds()  # a step's time counts its check: clients wait for both
                    touched = touched or bool(step.expect_holding)
                    sub_result = await self._run_step(run, step, f"step {index + 1} of {len(plan)}")
                    if is_inspection(step):
                        self._check_look(step, sub_result)
                    else:
                        await self._check_post(step, label)
                    self.step_durations.record(step, self._robot_seconds() - started, run.task)
                run.index, run.phase = len(plan), "done"
                run.publish()  # the last word is progress 1.0
                return self._finish(goal_handle, result, "", "done")
            except StepFailed as failure:
                if failure.code in RETREAT_AFTER:
                    await self._retreat(run, plan)
                return self._finish(goal_handle, result, failure.code, failure.message)
            except Exception as error:  # noqa: BLE001 - every goal ends with a result
                log.exception("task failed")
                return self._finish(goal_handle, result, ErrorCodes.INTERNAL, f"internal error: {error}")
            finally:  # before the result leaves (rclpy sends it once this coroutine returns)
                self.inventory.settle(
                    result.labware_id,
                    (destination, GRIPPER, source),
                    self.robot_state,
                    self._sensed_nests(),
                    self.workcell.sensors if self.workcell is not None else None,
                    camera_nests=self.camera_nests,
                    unsensed_at=destination if result.success else (None if touched else source),
                )
                result.inventory_revision = self.inventory.revision
                self.task_ended_at = time.monotonic()
                self.active = None

        return execute

    async def _run_step(self, run: TaskRun, step: Step, which: str) -> Any:
        return await run_step(self.node, self.clients[step.action], run, step, which, self.answering)

    async def _retreat(self, run: TaskRun, plan: list[Step]) -> None:
        """Best effort after the gripper was left empty: bring the arm out of the nest or pocket and
        tuck it; the task still ends with its failure, whatever happens here."""
        for step in retreat_steps(plan, run.index):
            try:
                run.phase = step.phase
                run.publish()
                await self._run_step(run, step, "retreat")
            except StepFailed as failure:
                log.warning("retreat after the failure stopped: %s", failure.message)
                return

    def _check_look(self, step: Step, sub_result: Any) -> None:
        """An inspection's post-condition, from its result: what the head camera saw in the nest."""
        expect = step.post
        assert expect is not None and isinstance(expect.holder, Nest)
        occupied = bool(sub_result.nest_occupied)
        if not expect.empty:  # a look after the place: a plate there is the task's (a look before is not)
            self.camera_nests[expect.holder] = occupied
        if expect.empty and not occupied or not expect.empty and sub_result.plate_seated:
            return
        seen = "a plate" if occupied else "no plate"
        if occupied and not expect.empty:
            seen = "a plate, but not seated (not level at a plate's height)"
        raise StepFailed(
            expect.code, f"after {step.phase}: the head camera sees {seen} in nest {expect.holder}"
        )

    async def _check_post(self, step: Step, labware_id: str) -> None:
        """The step's post-condition, read from sensor reports taken after the step ended.

        Which reports those are: a /robot_state received after the result that shows the robot
        idle was read between this goal's end and the next goal's start (the robot reports
        "manipulating" or "navigating" while a goal runs, and the sensors and that state come from
        one instant); /station_states from the same instant or later arrive after it. A report
        merely received after the result may have been read before the step ended."""
        expect = step.post
        if expect is None:
            return
        ended, topic = time.monotonic(), topic_of(expect)
        deadline, idle_at = ended + float(self.param("post_check_s")), None
        seen = ""
        while True:
            if idle_at is None and self.idle_report_at > ended:
                idle_at = self.idle_report_at
            if idle_at is not None and self.state_times.get(topic, -1e9) >= idle_at:
                seen = unmet(expect, labware_id, self.robot_state, self.station_states)
                if not seen:
                    return
            if time.monotonic() >= deadline:
                if not seen:
                    no_report = f"no {STATE_TOPICS[topic]} read after the step within {deadline - ended:g} s"
                    raise StepFailed(ErrorCodes.INTERNAL, f"after {step.phase}: {no_report}")
                raise StepFailed(expect.code, f"after {step.phase}: {seen} ({step.describe()})")
            self.report_arrived = Future()  # completed by the next state message
            await within(self.node, self.report_arrived, deadline - time.monotonic())

    def _robot_seconds(self) -> float:
        """The robot's clock as its last state report carried it (simulated time in the twin)."""
        stamp = self.robot_state.stamp if self.robot_state is not None else None
        return stamp.sec + stamp.nanosec * 1e-9 if stamp is not None else 0.0

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
