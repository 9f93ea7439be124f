"""The standard's labware transfer as data: six steps, eight commands, in the order SiLA fixes.

SiLA labware transfer v1.0: the source device gets PrepareForOutput and the destination
PrepareForInput (at the same time, so they form one step); the active device (the robot) then
does GetLabware when it is the destination, PutLabware when it is the source; then the passive
device hears LabwareRemoved or LabwareDelivered. A transfer between two stations is therefore a
pick (station to robot) followed by a place (robot to station):

    A.PrepareForOutput + Robot.PrepareForInput    Robot.GetLabware    A.LabwareRemoved
    B.PrepareForInput + Robot.PrepareForOutput    Robot.PutLabware    B.LabwareDelivered

A is the source station, B the destination. Step names are these strings everywhere (progress
records, the demo's timings, campaign reports); command names in errors use the real station
name ("station_a.PrepareForOutput"). Stations are passive nests without storage of their own, so
they get internal position 1, as the standard asks of such devices; the robot's internal position
is its hotel slot.

Threads: any; these functions only build callables, which `run_step` calls.
"""

from __future__ import annotations

from typing import Any

from sila_labware.client.steps import Command

PREPARE_SOURCE = "A.PrepareForOutput + Robot.PrepareForInput"
GET_LABWARE = "Robot.GetLabware"
LABWARE_REMOVED = "A.LabwareRemoved"
PREPARE_DESTINATION = "B.PrepareForInput + Robot.PrepareForOutput"
PUT_LABWARE = "Robot.PutLabware"
LABWARE_DELIVERED = "B.LabwareDelivered"
PICK_STEPS = (PREPARE_SOURCE, GET_LABWARE, LABWARE_REMOVED)
PLACE_STEPS = (PREPARE_DESTINATION, PUT_LABWARE, LABWARE_DELIVERED)
TRANSFER_STEPS = PICK_STEPS + PLACE_STEPS

STATION_INTERNAL_POSITION = 1

StepPlan = list[tuple[str, list[Command]]]
"""(step name, the commands started together in it), in order."""


def pick_sequence(
    manipulator: Any,
    site: Any,
    handover: tuple[str, int],
    internal_position: int,
    labware_type: str,
    labware_id: str,
) -> StepPlan:
    """Station `handover` -> the robot's `internal_position` (the features are sila2 client features)."""
    station = handover[0]
    return [
        (
            PREPARE_SOURCE,
            [
                Command(
                    f"{station}.PrepareForOutput",
                    lambda: site.PrepareForOutput(
                        HandoverPosition=handover, InternalPosition=STATION_INTERNAL_POSITION
                    ),
                ),
                Command(
                    "Robot.PrepareForInput",
                    lambda: manipulator.PrepareForInput(
                        HandoverPosition=handover,
                        InternalPosition=internal_position,
                        LabwareType=labware_type,
                        LabwareUniqueID=labware_id,
                    ),
                ),
            ],
        ),
        (
            GET_LABWARE,
            [
                Command(
                    "Robot.GetLabware",
                    lambda: manipulator.GetLabware(HandoverPosition=handover, IntermediateActions=[]),
                )
            ],
        ),
        (
            LABWARE_REMOVED,
            [Command(f"{station}.LabwareRemoved", lambda: site.LabwareRemoved(HandoverPosition=handover))],
        ),
    ]


def place_sequence(
    manipulator: Any,
    site: Any,
    handover: tuple[str, int],
    internal_position: int,
    labware_type: str,
    labware_id: str,
) -> StepPlan:
    """The robot's `internal_position` -> station `handover`; the station is told the plate's id
    and type."""
    station = handover[0]
    return [
        (
            PREPARE_DESTINATION,
            [
                Command(
                    f"{station}.PrepareForInput",
                    lambda: site.PrepareForInput(
                        HandoverPosition=handover,
                        InternalPosition=STATION_INTERNAL_POSITION,
                        LabwareType=labware_type,
                        LabwareUniqueID=labware_id,
                    ),
                ),
                Command(
                    "Robot.PrepareForOutput",
                    lambda: manipulator.PrepareForOutput(
                        HandoverPosition=handover, InternalPosition=internal_position
                    ),
                ),
            ],
        ),
        (
            PUT_LABWARE,
            [
                Command(
                    "Robot.PutLabware",
                    lambda: manipulator.PutLabware(HandoverPosition=handover, IntermediateActions=[]),
                )
            ],
        ),
        (
            LABWARE_DELIVERED,
            [
                Command(
                    f"{station}.LabwareDelivered", lambda: site.LabwareDelivered(HandoverPosition=handover)
                )
            ],
        ),
    ]
