"""Every wait of the sequencer ends: a /describe_workcell that never answers, a robot that never
reports its state. The sequencer runs as a real process over DDS; the robot side is a small real
peer (tests/helpers/silent_workcell.py) whose /describe_workcell answers only when the test lets it.

(A sub-action past `step_timeout_s` is tested against the real simulation in
test_ros_transfer.py: test_a_step_past_step_timeout_s_is_cancelled_and_the_task_aborts_naming_it.)
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml
from action_msgs.msg import GoalStatus
from labware_interfaces.action import GetLabware
from labware_interfaces.msg import ErrorCodes

from tests.helpers.ros_processes import RosCaller, running
from tiago_sim.sequencer.startup import DEFAULT_PARAMS


@dataclass
class Bounds:
    caller: RosCaller
    peer_log: Path
    answer_when: Path

    def requests(self) -> int:
        return self.peer_log.read_text().count("REQUEST")


@pytest.fixture(scope="module")
def bounds(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Bounds]:
    directory = tmp_path_factory.mktemp("bounds")
    params = yaml.safe_load(DEFAULT_PARAMS.read_text())
    params.update(describe_timeout_s=0.3, describe_attempts=2, server_wait_s=1.0)
    params_file = directory / "sequencer.yaml"
    params_file.write_text(yaml.safe_dump(params))
    answer_when, peer_log, log_path = (
        directory / "answer",
        directory / "peer.log",
        directory / "sequencer.log",
    )
    with (
        running("tests.helpers.silent_workcell", "--answer-when", str(answer_when), log_path=peer_log),
        running("tiago_sim.sequencer", "--params", str(params_file), log_path=log_path) as process,
    ):
        caller = RosCaller("test_sequencer_bounds")
        try:
            caller.wait_for(lambda: "READY" in peer_log.read_text(), 30.0, "the silent workcell")
            caller.action_client(GetLabware, "/get_labware", timeout_s=60.0)
            yield Bounds(caller, peer_log, answer_when)
        finally:
            caller.close()
        assert process.poll() is None, f"the sequencer died; see {log_path}"
    assert "Traceback" not in log_path.read_text(), "the sequencer logged a traceback"


def get_goal() -> GetLabware.Goal:
    return GetLabware.Goal(
        handover_position="station_a", sub_position=1, internal_position=1, labware_id="P1"
    )


def test_a_describe_workcell_that_never_answers_ends_the_goal_after_its_attempts(bounds: Bounds) -> None:
    started = time.monotonic()
    outcome = bounds.caller.call_action(GetLabware, "/get_labware", get_goal(), timeout_s=30.0)
    took_s = time.monotonic() - started
    assert outcome.status == GoalStatus.STATUS_ABORTED
    assert outcome.result.error_code == ErrorCodes.INTERNAL
    assert outcome.result.message == (
        "robot not available: /describe_workcell answered none of 2 requests in 0.3 s"
    )
    assert bounds.requests() == 2
    assert took_s < 5.0, f"2 attempts of 0.3 s took {took_s:.1f} s"


def test_once_it_answers_the_next_wait_is_bounded_too(bounds: Bounds) -> None:
    """The workcell comes now; no /robot_state ever does: the goal ends after server_wait_s."""
    bounds.answer_when.touch()
    started = time.monotonic()
    outcome = bounds.caller.call_action(GetLabware, "/get_labware", get_goal(), timeout_s=30.0)
    assert outcome.result.error_code == ErrorCodes.INTERNAL
    assert "robot not available: /robot_state and /station_states does not answer" in outcome.result.message
    assert time.monotonic() - started < 5.0
