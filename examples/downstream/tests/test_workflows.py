"""A lab's workflows, each against the simulated lab reset to its world file (default lab: a plate
`plate_001` in station_a's nest 1; station_a and station_b have two nests each)."""

from __future__ import annotations

import pytest

from labware_model.holders import Nest
from sila_labware.client.errors import (
    InvalidCommandSequence,
    LabwareNotPicked,
    LabwareNotPlaced,
    ParameterRejected,
    UnknownLabware,
)
from sila_labware.testing.lab import SimulatedLabSession

PLATE = "plate_001"
A1, A2, B1, B2 = ("station_a", 1), ("station_a", 2), ("station_b", 1), ("station_b", 2)


def where(lab: SimulatedLabSession, plate: str = PLATE) -> tuple[str, int]:
    """(station, nest) where the robot's inventory says the plate is."""
    location = lab.client.locate(plate).location
    assert isinstance(location, Nest), f"{plate} is not in a nest but at {location}"
    return location.station, location.sub_position


@pytest.mark.parametrize("destination", [B1, B2, A2])
def test_a_plate_moves_to_another_nest(simulated_lab: SimulatedLabSession, destination) -> None:
    simulated_lab.client.transfer(A1, destination, labware_id=PLATE)
    assert where(simulated_lab) == destination


def test_a_plate_goes_out_and_comes_back(simulated_lab: SimulatedLabSession) -> None:
    simulated_lab.client.transfer(A1, B2, labware_id=PLATE)
    simulated_lab.client.transfer(B2, A1, labware_id=PLATE)
    assert where(simulated_lab) == A1


def test_an_unknown_plate_is_a_defined_error(simulated_lab: SimulatedLabSession) -> None:
    with pytest.raises(UnknownLabware):
        simulated_lab.client.locate("no_such_plate")


def test_picking_from_an_empty_nest_is_refused(simulated_lab: SimulatedLabSession) -> None:
    with pytest.raises(InvalidCommandSequence):
        simulated_lab.client.transfer(B1, A2, labware_id=PLATE)


def test_a_nest_that_does_not_exist_is_refused_before_anything_moves(
    simulated_lab: SimulatedLabSession,
) -> None:
    with pytest.raises(ParameterRejected):
        simulated_lab.client.transfer(A1, ("station_b", 3), labware_id=PLATE)
    assert simulated_lab.client.onboard_labware() == []


def test_a_plate_someone_took_away_is_not_picked(simulated_lab: SimulatedLabSession) -> None:
    simulated_lab.sila_client().SimulatedLabController.InjectFault(Fault="RemovePlate", Target=PLATE)
    with pytest.raises((LabwareNotPicked, InvalidCommandSequence)):
        simulated_lab.client.transfer(A1, B1, labware_id=PLATE)


def test_a_plate_knocked_out_of_the_nest_is_not_placed(simulated_lab: SimulatedLabSession) -> None:
    simulated_lab.sila_client().SimulatedLabController.InjectFault(Fault="KnockPlate", Target=PLATE)
    with pytest.raises(LabwareNotPlaced):
        simulated_lab.client.transfer(A1, B1, labware_id=PLATE)


def test_the_robot_drives_and_docks(simulated_lab: SimulatedLabSession) -> None:
    simulated_lab.client.undock()
    simulated_lab.client.drive_to("station_b_work")
    simulated_lab.client.dock()
