"""The grasp families for high nests: their pads' geometry against a plate and their reach from the model."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from tiago_description import robot_model as rm
from tiago_description.grasp_reach import Grasp, T_site_grasp, floor_gap_m, highest_nest, pad_on_wall_m
from tiago_description.reach_map import interpolated_ceiling


def _pad_corners_in_site(grasp: Grasp) -> np.ndarray:
    """The eight corners of both pads (their inner faces' extremes) in the nest frame."""
    half_gap = rm.FINGER_MOUNT_OFFSET + 0.08548 / 2
    corners = [
        (x, side * y, z, 1.0)
        for x, side, y, z in itertools.product(
            (rm.PAD_TIP - rm.PAD_LENGTH, rm.PAD_TIP),
            (1.0, -1.0),
            (half_gap, half_gap + rm.PAD_THICKNESS),
            (-rm.PAD_WIDTH / 2, rm.PAD_WIDTH / 2),
        )
    ]
    return (T_site_grasp(grasp) @ np.array(corners).T).T[:, :3]


@pytest.mark.parametrize(
    "grasp", [Grasp("top-down"), Grasp("rolled", 30.0), Grasp("rolled", -20.0), Grasp("pitched", 20.0)]
)
def test_every_grasp_keeps_the_top_down_gap_between_its_lowest_pad_point_and_the_floor(grasp: Grasp) -> None:
    lowest = _pad_corners_in_site(grasp)[:, 2].min()
    assert lowest == pytest.approx(floor_gap_m(), abs=1e-3)


def test_a_rolled_grasp_puts_its_pad_contact_over_the_plate_centre() -> None:
    corners = _pad_corners_in_site(Grasp("rolled", 30.0))
    contact = pad_on_wall_m(Grasp("rolled", 30.0))
    low = corners[np.argmin(corners[:, 2])]
    # the contact triangle runs from the lowest corner back along the plate; its centroid lies a third in
    centroid_along = low[0] - np.sign(low[0]) * contact / 3 * np.cos(np.radians(30.0))
    assert abs(centroid_along) < 2e-3


def test_the_pads_left_on_a_microplate_wall() -> None:
    assert pad_on_wall_m(Grasp("top-down")) == rm.PAD_WIDTH
    assert pad_on_wall_m(Grasp("rolled", 20.0)) == pytest.approx(0.0202, abs=5e-4)  # 7.35 mm / tan 20 deg
    assert (
        pad_on_wall_m(Grasp("pitched", 10.0)) == 0.0
    )  # the pad tips 17 mm apart in height, the wall 14.35 mm


def test_top_down_reach_agrees_with_the_shipped_map_and_a_pitched_grasp_reaches_higher() -> None:
    top_down = highest_nest(Grasp("top-down"), 0.55, -0.25)
    assert top_down == pytest.approx(interpolated_ceiling(0.55, -0.25), abs=0.01)
    pitched = highest_nest(Grasp("pitched", 20.0), 0.55, -0.25)
    assert pitched is not None and pitched > top_down + 0.05
