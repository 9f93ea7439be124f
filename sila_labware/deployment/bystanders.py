"""The plates a transfer did not move: are they still where they were, by physics ground truth?

Why: a transfer was judged by the plate it moved alone. A finger or a held plate that knocks another
plate out of its nest on the way changes the lab just as much: the scheduler's inventory then says
that plate is in a nest where it no longer lies, while the trial counted as delivered. The simulator
logs such a push (its plate-push watch) but stops nothing, as a real robot would not notice it either.
So the demo asks the robot side's ground truth about every other plate the world file names, before
and after the transfer, and a plate that was in place before and is not after fails the transfer.
For success checks only (/check_placement), never for control. Runs on the demo's thread.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from labware_model.holders import HotelSlot, Nest, location_text
from labware_model.readings import PlacementCheck
from ros_bridge.robot_link import RobotLink
from sila_labware.deployment.plate_names import plates_at_start

CHECK_TIMEOUT_S = 10.0


@dataclass(frozen=True)
class Bystander:
    """A plate the transfer is not about, and the nest or hotel slot it rests in."""

    labware_id: str
    holder: Nest | HotelSlot


def in_place(holder: Nest | HotelSlot, check: PlacementCheck) -> bool:
    """Physics says the plate rests where `holder` is: seated in the nest, or in the hotel slot."""
    if isinstance(holder, Nest):
        return check.found and check.in_nest
    return check.found and check.location == holder


def _check(link: RobotLink, bystander: Bystander) -> PlacementCheck:
    nest = bystander.holder if isinstance(bystander.holder, Nest) else None
    return link.check_placement(bystander.labware_id, nest, timeout_s=CHECK_TIMEOUT_S)


def bystanders_in_place(link: RobotLink, world: Path, moved: str, source: Nest) -> list[Bystander]:
    """The world file's plates but the one moved (`moved`, starting in `source`) that rest where the
    file puts them now: a plate already elsewhere is not the transfer's doing. Raises BridgeError."""
    starts = plates_at_start(world).items()
    candidates = [Bystander(name, at) for name, at in starts if name != moved and at != source]
    return [bystander for bystander in candidates if in_place(bystander.holder, _check(link, bystander))]


def moved_bystanders(link: RobotLink, before: Iterable[Bystander]) -> list[str]:
    """For each plate of `before` no longer in place: where physics finds it. Raises BridgeError."""
    moved = []
    for bystander in before:
        check = _check(link, bystander)
        if in_place(bystander.holder, check):
            continue
        where = location_text(check.location) if check.found else "nowhere the robot side knows"
        if check.found and check.location == bystander.holder:
            where += f", outside the nest's tolerance ({1000.0 * check.position_error_m:.1f} mm off centre"
            where += f", yaw {math.degrees(check.yaw_error_rad):.1f} deg)"
        moved.append(f"{bystander.labware_id} is no longer in {bystander.holder}: it is at {where}")
    return moved
