"""Step durations: the table until a step kind has run, then what it took (robot seconds)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.tiago_sim.sequencer.test_plans import WORKCELL, goal, robot, stations
from tiago_sim.sequencer.plans import Step, get_plan, put_plan
from tiago_sim.sequencer.startup import load_params
from tiago_sim.sequencer.step_durations import FALLBACK_S, StepDurations, step_kind, table_from_parameters

SEQUENCER_YAML = Path(__file__).resolve().parents[3] / "tiago_sim" / "sequencer" / "sequencer.yaml"
APPROACH = Step("marker_motion", {"station": "a", "sub_position": 1, "target": "work_pose"})
TOOL_MOVE = Step("marker_motion", {"station": "a", "sub_position": 1, "target": "site"})


def test_a_step_kind_names_the_action_and_what_it_does() -> None:
    assert step_kind(APPROACH) == "marker_motion:work_pose"
    assert step_kind(Step("navigate", {"poi": "station_b_work"})) == "navigate:station_b_work"
    assert step_kind(Step("play_motion", {"motion_name": "Tuck"})) == "play_motion:Tuck"
    # one motion in two parts of a plan: to the hotel from the bench, out of a pocket
    to_hotel = Step("play_motion", {"motion_name": "NestApproach", "hotel_slot": 1}, "to hotel")
    retract = Step("play_motion", {"motion_name": "NestApproach", "hotel_slot": 1}, "retract")
    assert (step_kind(to_hotel), step_kind(retract)) == (
        "play_motion:NestApproach:to_hotel",
        "play_motion:NestApproach:retract",
    )


def test_a_kind_is_counted_per_task() -> None:
    """The approach to a nest: short from the bench pose (GetLabware), long from the hotel (PutLabware)."""
    approach = Step(
        "marker_motion", {"station": "a", "sub_position": 1, "target": "site_approach"}, "approach"
    )
    assert step_kind(approach, "PutLabware") == "PutLabware:marker_motion:site_approach:approach"
    durations = StepDurations(table_from_parameters({"PutLabware.marker_motion.site_approach.approach": 3.3}))
    assert (durations.estimate(approach, "PutLabware"), durations.estimate(approach, "GetLabware")) == (
        3.3,
        3.0,
    )
    durations.record(approach, 1.0, "GetLabware")
    assert (durations.estimate(approach, "PutLabware"), durations.estimate(approach, "GetLabware")) == (
        3.3,
        1.0,
    )


def test_the_shipped_table_names_every_step_of_both_plans_at_a_station() -> None:
    """sequencer.yaml: no step of a task that starts at its station falls back to its action's row."""
    table = table_from_parameters(load_params(SEQUENCER_YAML)["estimates_s"])
    plans = (
        ("GetLabware", get_plan(goal(), WORKCELL, robot(), stations("P1"), "right")),
        ("PutLabware", put_plan(goal(), WORKCELL, robot({1: "P1", 2: ""}), stations(), "right")),
    )
    for task, plan in plans:
        missing = [step_kind(step, task) for step in plan if step_kind(step, task) not in table]
        assert missing == [], missing


def test_the_table_names_kinds_where_it_can_and_actions_for_the_rest() -> None:
    table = table_from_parameters({"marker_motion": 2.4, "marker_motion.site.reaching": 1.7})
    assert table == {"marker_motion": 2.4, "marker_motion:site:reaching": 1.7}
    durations = StepDurations(table)
    reaching = Step("marker_motion", {"station": "a", "sub_position": 1, "target": "site"}, "reaching")
    assert durations.estimate(reaching) == 1.7
    assert durations.estimate(APPROACH) == 2.4, "a kind the table does not name: its action's value"
    durations.record(reaching, 2.5)
    assert durations.estimate(reaching) == 2.5, "what the kind took wins over the table"


def test_the_table_serves_until_the_kind_ran_then_what_it_took() -> None:
    durations = StepDurations({"marker_motion": 2.4})
    assert durations.estimate(APPROACH) == durations.estimate(TOOL_MOVE) == 2.4
    durations.record(APPROACH, 5.0)
    assert durations.estimate(APPROACH) == 5.0
    assert durations.estimate(TOOL_MOVE) == 2.4, "another kind of the same action keeps the table's value"
    durations.record(APPROACH, 6.0)
    assert durations.estimate(APPROACH) == pytest.approx(5.5)


def test_an_unknown_action_gets_the_fallback_and_a_clock_restart_is_ignored() -> None:
    durations = StepDurations({})
    assert durations.estimate(Step("gripper", {"command": "open"})) == FALLBACK_S
    durations.record(APPROACH, -40.0)
    assert durations.estimate(APPROACH) == FALLBACK_S
