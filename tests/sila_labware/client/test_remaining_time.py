"""The remaining-time check: at each quarter of a step, what the client last heard, counted down,
against what really remained (sila_labware.client.remaining_time), on records as a client gets them."""

from __future__ import annotations

from dataclasses import asdict

import pytest

from sila_labware.benchmarks.campaign import TrialOutcome, format_table, summarize
from sila_labware.client.remaining_time import RemainingSampler, share_within
from sila_labware.client.steps import StepProgress


def feed(
    sampler: RemainingSampler, now: list[float], step: str, records: list[tuple[float, float | None]]
) -> None:
    """Records at wall times `at` with remaining `estimate`; the last one ends the step."""
    began = records[0][0]
    for index, (at, estimate) in enumerate(records):
        now[0] = at
        done = index == len(records) - 1
        sampler(StepProgress(step, 1.0 if done else 0.5, estimate, elapsed_s=at - began, done=done))


def sampler_with_clock() -> tuple[RemainingSampler, list[float]]:
    now = [0.0]
    return RemainingSampler(clock=lambda: now[0]), now


def test_an_estimate_that_counts_down_to_the_end_is_within_at_every_quarter() -> None:
    sampler, now = sampler_with_clock()
    feed(sampler, now, "GetLabware", [(0.0, 10.0), (1.0, 9.0), (4.0, 6.0), (8.0, 2.0), (10.0, None)])
    (check,) = sampler.checks
    assert check.duration_s == 10.0
    assert check.errors == pytest.approx((0.0, 0.0, 0.0))
    assert check.within


def test_a_step_without_estimates_misses_every_quarter() -> None:
    sampler, now = sampler_with_clock()
    feed(sampler, now, "Undock", [(0.0, None), (5.0, None), (10.0, None)])
    (check,) = sampler.checks
    assert check.errors == (None, None, None) and not check.within


def test_an_estimate_that_stays_high_is_outside_once_it_is_off_by_a_tenth() -> None:
    sampler, now = sampler_with_clock()
    # says 15 s at the start, then nothing new: at 2.5 s it counts down to 12.5 (real 7.5: +50 %)
    feed(sampler, now, "PutLabware", [(0.0, 15.0), (10.0, None)])
    feed(sampler, now, "GetLabware", [(10.0, 10.0), (20.0, None)])  # a second step, exact
    put, get = sampler.checks
    assert put.errors == pytest.approx((0.5, 0.5, 0.5)) and not put.within
    assert get.step == "GetLabware" and get.within
    assert share_within(sampler.checks) == 0.5


def test_steps_shorter_than_a_second_are_not_judged() -> None:
    sampler, now = sampler_with_clock()
    feed(sampler, now, "A.LabwareRemoved", [(0.0, None), (0.05, None)])
    feed(sampler, now, "Robot.GetLabware", [(1.0, 10.0), (11.0, None)])
    removed, get = sampler.checks
    assert not removed.judged and get.judged
    assert share_within(sampler.checks) == 1.0


def test_a_campaigns_table_judges_the_estimates_only_when_it_ran_paced() -> None:
    """Unpaced, the robot's clock races through motions and crawls while the software computes: no
    wall-time estimate can hold, so the table says nothing of them (the JSON keeps the numbers)."""
    sampler, now = sampler_with_clock()
    feed(sampler, now, "Robot.GetLabware", [(0.0, 10.0), (10.0, None)])
    outcome = TrialOutcome(
        1, True, "", "", 60.0, 10.0, 1.0, 1.0, remaining=[asdict(c) for c in sampler.checks]
    )
    summary = summarize([outcome], {}, 1)
    assert summary["remaining_time"]["within"] == 1
    assert "remaining-time estimates" not in format_table({**summary, "pace": None})
    assert "remaining-time estimates within 10 %" in format_table({**summary, "pace": 1.0})
