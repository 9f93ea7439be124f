"""The furniture-lab acceptance check judges a lab as `world check` does: the loader and the ways."""

from __future__ import annotations

from pathlib import Path

import yaml

from tiago_sim.layouts.acceptance import check_lab, reason_kind

FIXTURES = Path(__file__).resolve().parent / "fixtures"


def _raw(name: str) -> dict:
    return yaml.safe_load((FIXTURES / name).read_text())


def test_a_lab_the_loader_accepts_but_the_robot_cannot_leave_is_refused_for_its_ways() -> None:
    """Layout 207077 loads (every nest reached, every marker seen) but shuts the robot in at two of
    the labeler's working poses: the check refuses it, and sorts the refusal as the robot's ways."""
    verdict = check_lab(207077, _raw("layout_207077.yaml"))
    assert not verdict.accepted
    assert len(verdict.problems) == 2
    assert {reason_kind(problem) for problem in verdict.problems} == {"no way for the robot"}


def test_a_lab_the_robot_serves_and_drives_is_accepted() -> None:
    assert check_lab(207020, _raw("layout_207020.yaml")).accepted


def test_a_final_approach_past_the_dock_is_refused_as_no_room_for_the_base() -> None:
    verdict = check_lab(212010, _raw("layout_212010.yaml"))
    assert not verdict.accepted
    assert [reason_kind(problem) for problem in verdict.problems] == ["no room for the base"]
