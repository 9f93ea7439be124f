"""The arm's way back off a bench, clear of what stands on it, and the boxes both ways are checked
against.

Why: after a place at a nest near the top of the arm's reach, the straight line back to the bench's
front line found no IK on its way (the wrist turns over near the body), and the one unchecked
joint-space move that replaced it swept a finger through the plate just placed: pushed 3.1 mm, out of
its nest, PLACE_FAILED (random layout 208108). The way back is now chosen as the way in is
(`bench_route`): against the station's marker board, its bench and the labware in its nests, placed
where the marker was seen from where the base still stands. Lives on the goal's thread.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from lab_description.world import Station
from tiago_description.arm_clearance import Box, HeldBox
from tiago_skills.behaviours import TOOL_SPEED_FREE
from tiago_skills.bench_route import BenchRoute, nest_labware_boxes, station_boxes
from tiago_skills.goal_run import GoalRun
from tiago_skills.marker_sighting import MarkerSighting


class BenchExit:
    """Remembers, per arm, the station and nest it last worked over; plans its way back from there."""

    def __init__(
        self,
        route: BenchRoute,
        held_plate: HeldBox,
        largest_labware: tuple[float, float, float],
        sighting_here: Callable[[GoalRun, str], MarkerSighting | None],
    ) -> None:
        """`sighting_here(run, station)`: the station's marker sighting if the base has not moved since."""
        self.route = route
        self.held_plate = held_plate
        self.largest_labware = largest_labware
        self.sighting_here = sighting_here
        self.worked_over: dict[str, tuple[Station, int]] = {}

    def over(self, arm: str, station: Station, sub_position: int) -> None:
        self.worked_over[arm] = (station, sub_position)

    def boxes(
        self, station: Station, sighting: MarkerSighting, sub_position: int, holding: bool
    ) -> list[Box]:
        """The board, the bench and labware in every nest but the one a held plate came from or goes
        into (the skills do not read the nests' sensors; the sequencer checked that one)."""
        stocked = [n for n in range(1, station.sub_positions + 1) if not (holding and n == sub_position)]
        return station_boxes(station, sighting.T_base_marker) + nest_labware_boxes(
            station, sighting.T_base_marker, stocked, self.largest_labware
        )

    def held(self, arm: str) -> HeldBox | None:
        return self.held_plate if self.route.behaviours.holding.get(arm, False) else None

    def __call__(self, run: GoalRun, arm: str, T_front: np.ndarray, span: tuple[float, float]) -> bool:
        """Move the tool to `T_front` by the first clear way (IK_FAILED if none is); False, without
        moving, where the arm has worked over no station seen from where the base stands."""
        if arm not in self.worked_over:
            return False
        station, sub_position = self.worked_over[arm]
        sighting = self.sighting_here(run, station.name)
        if sighting is None:
            return False
        held = self.held(arm)
        boxes = self.boxes(station, sighting, sub_position, held is not None)
        self.route.move(run, arm, [T_front], TOOL_SPEED_FREE, span, boxes, held)
        return True
