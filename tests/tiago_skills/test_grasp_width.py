"""A grasp is a plate held flat only if the fingers stopped its short side apart.

Seen in the default lab (trial 142025): a finger came down on a plate's edge and tipped it; the
fingers closed 75 mm apart on an 85.5 mm plate (and 14 mm apart on its replay), the grasp counted,
and the plate fell over in the hotel. The check turns that into GRASP_FAILED at the nest.
"""

from __future__ import annotations

import math

import pytest

from tiago_skills.grasp_check import GRASP_WIDTH_TOLERANCE_M, grasp_width_problem

SBS = 0.08548
HEIGHT = 0.01435


def tilted_span(tilt_deg: float) -> float:
    """How far apart level pads stand on a plate turned `tilt_deg` about its long side."""
    tilt = math.radians(tilt_deg)
    return SBS * math.cos(tilt) + HEIGHT * math.sin(tilt)


@pytest.mark.parametrize("opening", [SBS, SBS - 0.002, SBS + 0.003, tilted_span(15.0), tilted_span(25.0)])
def test_a_plate_held_flat_or_nearly_passes(opening: float) -> None:
    assert grasp_width_problem(opening, (0.0762, SBS)) == ""


@pytest.mark.parametrize("opening", [0.0753, 0.0143, tilted_span(35.0), SBS + 0.006])
def test_fingers_closed_on_a_tipped_plate_are_refused_naming_the_widths(opening: float) -> None:
    problem = grasp_width_problem(opening, (SBS,))
    assert f"closed {1000 * opening:.1f} mm apart" in problem and "nearest 85.5 mm" in problem


def test_the_tolerance_lets_pass_what_pad_compliance_and_small_tilts_give() -> None:
    assert abs(tilted_span(25.0) - SBS) < GRASP_WIDTH_TOLERANCE_M < abs(tilted_span(35.0) - SBS)


def test_without_known_plates_no_grasp_is_refused() -> None:
    assert grasp_width_problem(0.03, ()) == ""
