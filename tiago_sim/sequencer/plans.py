"""The sub-action plans of GetLabware and PutLabware, and the checks before a plan starts.

Pure data: a plan is a list of Steps (which action, which goal fields, an estimated duration,
and what a sensor must show once the step has ended), built from the goal, the workcell
/describe_workcell reported (a `WorkcellDescription` of the labware model) and what the robot and
stations report. The sequencer node runs it and checks each step's `post` against /robot_state
and /station_states (see `postconditions`). Safe on any thread.

Post-conditions, at the points where a plate changes hands or has been carried:

| step | sensor | error when it fails |
|---|---|---|
| grasp (gripper closed) | the gripper's own result: something between the fingers | GRASP_FAILED |
| lifting out of the nest or pocket; the last carrying step | gripper holds the plate | PLATE_SLIPPED |
| release into the hotel (GetLabware) | hotel slot sees the plate | PLACE_FAILED |
| arm tucked (GetLabware's last step) | hotel slot still sees it | PLATE_SLIPPED |
| final approach (PutLabware, before reaching into the hotel) | hotel slot still sees it | PLATE_SLIPPED |
| release into the nest (PutLabware) | nest sensor sees the plate | PLACE_FAILED |
| arm tucked (PutLabware's last step) | nest sensor still sees it | PLACE_FAILED |

A lab whose nests or hotel have no sensors (`LabSensors`, a stock TIAGo++) checks otherwise:
- no nest sensors: the head camera looks into the destination nest after the final approach (a
  plate there: NEST_OCCUPIED) and once the arm is tucked (no plate: PLACE_FAILED); a source nest is
  checked by the grasp itself (nothing between the fingers: GRASP_FAILED);
- no hotel sensors: the gripper holding the plate down in the pocket before it lets go is the
  check of a place into the hotel, and the grasp from it the check of a pick (GRASP_FAILED);
- before anything moves, the inventory stands in for a missing sensor: a slot or nest it records
  a plate in is full, a slot it records none in is empty.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from labware_interfaces.msg import ErrorCodes, RobotState

from labware_model.holders import GRIPPER, Gripper, HotelSlot, Location, Nest
from labware_model.workcell import WorkcellDescription

# Refusals that rest on what the state topics say (a slot or nest full or empty), not on the goal.
STATE_REFUSALS = frozenset(
    {ErrorCodes.SLOT_OCCUPIED, ErrorCodes.GRASP_FAILED, ErrorCodes.NEST_OCCUPIED, ErrorCodes.SLOT_EMPTY}
)


class TaskRefused(Exception):
    """The goal cannot be done; nothing has moved yet."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message


@dataclass(frozen=True)
class Expect:
    """What a sensor must show once a step has ended: the task's plate in `holder` (the gripper, a
    hotel slot or a nest); `code` is the ErrorCodes value the task fails with when it does not."""

    holder: Gripper | HotelSlot | Nest
    code: str
    empty: bool = False  # the holder must hold no plate (a nest the head camera checks before a place)


@dataclass(frozen=True)
class Step:
    action: str  # undock, navigate, play_motion, gripper, marker_motion
    goal: dict[str, Any] = field(default_factory=dict)
    phase: str = ""
    expect_holding: bool | None = None  # gripper close: True means "must hold a plate"
    post: Expect | None = None  # checked on the state topics once the step has ended

    def describe(self) -> str:
        details = " ".join(f"{k}={v}" for k, v in self.goal.items() if k != "arm")
        return f"{self.action} {details}".strip()


@dataclass(frozen=True)
class CheckedGoal:
    """A goal's places, once they are known to exist: the nest, the hotel slot, the station's POI."""

    nest: Nest
    hotel_slot: HotelSlot
    poi: str


def check_common(goal: Any, workcell: WorkcellDescription) -> CheckedGoal:
    """Station, sub-position and hotel slot exist; returns them with the station's POI."""
    station = workcell.station(goal.handover_position)
    if station is None:
        known = ", ".join(sorted(s.name for s in workcell.stations))
        raise TaskRefused(
            ErrorCodes.UNKNOWN_STATION, f"unknown station {goal.handover_position!r}: known are {known}"
        )
    if not 1 <= goal.sub_position <= station.sub_positions:
        raise TaskRefused(
            ErrorCodes.UNKNOWN_SLOT,
            f"station {goal.handover_position} has sub-positions 1..{station.sub_positions}, "
            f"not {goal.sub_position}",
        )
    if not 1 <= goal.internal_position <= workcell.hotel_slots:
        raise TaskRefused(
            ErrorCodes.UNKNOWN_SLOT,
            f"unknown hotel slot {goal.internal_position}: the robot has 1..{workcell.hotel_slots}",
        )
    return CheckedGoal(Nest(station.name, goal.sub_position), HotelSlot(goal.internal_position), station.poi)


# The inventory's plate at a holder: its name ("" for an unnamed plate), None when it records none.
BookLookup = Callable[[Location], "str | None"]


def nest_state(station_states: Any, nest: Nest) -> Any | None:
    """The NestState message of `nest` in a StationStates message, if it reports that nest (none
    when the lab's nests have no sensors: `station_states` is None)."""
    if station_states is None:
        return None
    for state in station_states.nests:
        if state.station == nest.station and state.sub_position == nest.sub_position:
            return state
    return None


def hotel_slot_state(robot_state: Any, slot: HotelSlot) -> Any | None:
    """The HotelSlot message of `slot` in a RobotState message, if it reports that slot (none when
    the hotel has no sensors: `robot_state` is None)."""
    if robot_state is None:
        return None
    for state in robot_state.hotel:
        if state.index == slot.index:
            return state
    return None


def ends_of(request: Any, from_hotel: bool) -> tuple[HotelSlot | Nest, HotelSlot | Nest]:
    """Where a goal takes its plate from and where it puts it: (hotel slot, nest) for PutLabware,
    (nest, hotel slot) for GetLabware."""
    slot, nest = HotelSlot(request.internal_position), Nest(request.handover_position, request.sub_position)
    return (slot, nest) if from_hotel else (nest, slot)


def label_at_source(request: Any, robot_state: Any, station_states: Any, from_hotel: bool) -> str:
    """The label the source's reader reads off the goal's plate ("" where none was read): the
    plate's physical identity, which the post-conditions compare with what later readers read. The
    goal's id is a name, not a label (see labware_model.inventory)."""
    if from_hotel and robot_state is not None:
        slot = hotel_slot_state(robot_state, HotelSlot(request.internal_position))
        return slot.labware_id if slot is not None else ""
    if not from_hotel and station_states is not None:
        nest = nest_state(station_states, Nest(request.handover_position, request.sub_position))
        return nest.labware_id if nest is not None else ""
    return ""


def travel_steps(robot_state: Any, poi: str) -> list[Step]:
    """Arm tucked, off the dock, drive to the station's POI - whatever of it is needed.

    The torso goes down to the travel height during the drive (navigate overlaps the two)."""
    if robot_state.current_poi == poi and robot_state.state != RobotState.STATE_DOCKED:
        return []
    steps = [Step("play_motion", {"motion_name": "Tuck"}, "arm tucked")]
    if robot_state.state == RobotState.STATE_DOCKED:
        steps.append(Step("undock", {}, "undocking"))
    steps.append(Step("navigate", {"poi": poi}, "driving"))
    return steps


def _goal_fields(checked: CheckedGoal, arm: str) -> tuple[dict[str, Any], dict[str, Any]]:
    """The goal fields of the nest's MarkerMotion steps and of the hotel slot's PlayMotion steps."""
    site = {"station": checked.nest.station, "sub_position": checked.nest.sub_position, "arm": arm}
    hotel = {"hotel_slot": checked.hotel_slot.index, "arm": arm}
    return site, hotel


def _recorded(book: BookLookup, holder: Location) -> str | None:
    """What the inventory records at `holder`, in words; None when it records no plate there."""
    name = book(holder)
    if name is None:
        return None
    return (
        f"{name} (by the inventory: it has no sensor)"
        if name
        else "a plate (by the inventory: it has no sensor)"
    )


def get_plan(
    goal: Any,
    workcell: WorkcellDescription,
    robot_state: Any,
    station_states: Any,
    arm: str,
    book: BookLookup = lambda _holder: None,
) -> list[Step]:
    """Checks, then the steps that take a plate from a station nest into a hotel slot."""
    checked = check_common(goal, workcell)
    sensors = workcell.sensors
    if sensors.hotel:
        slot = hotel_slot_state(robot_state, checked.hotel_slot)
        occupied = slot is not None and (slot.occupied or slot.labware_id)
        occupant = (slot.labware_id or "a plate whose label its reader could not read") if occupied else None
    else:
        occupant = _recorded(book, checked.hotel_slot)
    if occupant is not None:
        raise TaskRefused(
            ErrorCodes.SLOT_OCCUPIED, f"hotel slot {goal.internal_position} already holds {occupant}"
        )
    if sensors.nests:  # else the grasp is the check: nothing between the fingers is GRASP_FAILED
        nest = nest_state(station_states, checked.nest)
        if nest is None or not nest.occupied:
            raise TaskRefused(
                ErrorCodes.GRASP_FAILED, f"no plate at source {goal.handover_position}:{goal.sub_position}"
            )
    site, hotel = _goal_fields(checked, arm)
    held = Expect(GRIPPER, ErrorCodes.PLATE_SLIPPED)
    in_slot = Expect(checked.hotel_slot, ErrorCodes.PLACE_FAILED) if sensors.hotel else None
    still_in_slot = Expect(checked.hotel_slot, ErrorCodes.PLATE_SLIPPED) if sensors.hotel else None
    return [
        *travel_steps(robot_state, checked.poi),
        Step("marker_motion", {**site, "target": "work_pose"}, "final approach"),
        Step("play_motion", {"motion_name": "Benchtop", "arm": arm}, "arm to bench"),
        Step("gripper", {"command": "open", "arm": arm}, "opening"),
        Step("marker_motion", {**site, "target": "site_approach"}, "approach"),
        Step("marker_motion", {**site, "target": "site"}, "reaching"),
        Step("gripper", {"command": "close", "arm": arm}, "grasp", expect_holding=True),
        Step("marker_motion", {**site, "target": "site_approach"}, "lifting", post=held),
        Step("play_motion", {"motion_name": "NestApproach", **hotel}, "to hotel"),
        Step("play_motion", {"motion_name": "Nest", **hotel}, "into hotel", post=held),
        Step("gripper", {"command": "open", "arm": arm}, "release", post=in_slot),
        Step("play_motion", {"motion_name": "NestApproach", **hotel}, "retract"),
        Step("play_motion", {"motion_name": "Tuck", "arm": arm}, "arm tucked", post=still_in_slot),
    ]


def put_plan(
    goal: Any,
    workcell: WorkcellDescription,
    robot_state: Any,
    station_states: Any,
    arm: str,
    book: BookLookup = lambda _holder: None,
) -> list[Step]:
    """Checks, then the steps that take a plate from a hotel slot into a station nest."""
    checked = check_common(goal, workcell)
    sensors = workcell.sensors
    where = f"destination {goal.handover_position}:{goal.sub_position}"
    if sensors.nests:
        nest = nest_state(station_states, checked.nest)
        if nest is not None and nest.occupied:
            holder = f" (holds {nest.labware_id})" if nest.labware_id else ""
            raise TaskRefused(ErrorCodes.NEST_OCCUPIED, f"{where} is occupied{holder}")
    else:
        occupant = _recorded(book, checked.nest)
        if occupant is not None:
            raise TaskRefused(ErrorCodes.NEST_OCCUPIED, f"{where} holds {occupant}")
    if sensors.hotel:
        slot = hotel_slot_state(robot_state, checked.hotel_slot)
        empty = slot is None or not (slot.occupied or slot.labware_id)
    else:
        empty = book(checked.hotel_slot) is None
    if empty:
        by = "" if sensors.hotel else " (by the inventory: the hotel has no sensors)"
        raise TaskRefused(ErrorCodes.SLOT_EMPTY, f"hotel slot {goal.internal_position} holds no plate{by}")
    site, hotel = _goal_fields(checked, arm)
    held = Expect(GRIPPER, ErrorCodes.PLATE_SLIPPED)
    placed = Expect(checked.nest, ErrorCodes.PLACE_FAILED)
    # With nest sensors, they check the place; without, the head camera does, before and after.
    sensed_place = placed if sensors.nests else None
    look_first, look_after = (
        ([], [])
        if sensors.nests
        else (
            [
                inspect_step(
                    site, "checking the nest is free", Expect(checked.nest, ErrorCodes.NEST_OCCUPIED, True)
                )
            ],
            [inspect_step(site, "checking the plate is in the nest", placed)],
        )
    )
    return [
        *travel_steps(robot_state, checked.poi),
        Step(
            "marker_motion",
            {**site, "target": "work_pose"},
            "final approach",
            post=Expect(checked.hotel_slot, ErrorCodes.PLATE_SLIPPED) if sensors.hotel else None,
        ),
        *look_first,
        Step("gripper", {"command": "open", "arm": arm}, "opening"),
        Step("play_motion", {"motion_name": "NestApproach", **hotel}, "to hotel"),
        Step("play_motion", {"motion_name": "Nest", **hotel}, "into hotel"),
        Step("gripper", {"command": "close", "arm": arm}, "grasp", expect_holding=True),
        Step("play_motion", {"motion_name": "NestApproach", **hotel}, "lifting", post=held),
        Step("marker_motion", {**site, "target": "site_approach"}, "approach"),  # via the carry height
        Step("marker_motion", {**site, "target": "site"}, "placing", post=held),
        Step("gripper", {"command": "open", "arm": arm}, "release", post=sensed_place),
        Step("marker_motion", {**site, "target": "site_approach"}, "retract"),
        Step("play_motion", {"motion_name": "Tuck", "arm": arm}, "arm tucked", post=sensed_place),
        *look_after,
    ]


def inspect_step(site: dict[str, Any], phase: str, post: Expect) -> Step:
    """A look into the nest with the head camera; its result, not a state topic, settles `post`."""
    return Step("marker_motion", {**site, "target": "inspect"}, phase, post=post)


def is_inspection(step: Step) -> bool:
    return step.action == "marker_motion" and step.goal.get("target") == "inspect"


# Task errors after which the gripper is empty and the arm may stand in a nest or a hotel pocket.
RETREAT_AFTER = frozenset({ErrorCodes.GRASP_FAILED, ErrorCodes.PLATE_SLIPPED, ErrorCodes.PLACE_FAILED})


def way_out(step: Step) -> Step | None:
    """The step that backs the arm out of where `step` put it: from a nest (marker_motion to the
    site) to the site's approach, from a hotel pocket (Nest) to its approach; None elsewhere."""
    if step.action == "marker_motion" and step.goal.get("target") == "site":
        return Step("marker_motion", {**step.goal, "target": "site_approach"}, "backing out")
    if step.action == "play_motion" and step.goal.get("motion_name") == "Nest":
        return Step("play_motion", {**step.goal, "motion_name": "NestApproach"}, "backing out")
    return None


def _moves_the_arm(step: Step) -> bool:
    """Play motions, and marker motions of the tool (the final approach to the work pose moves the base)."""
    return step.action == "play_motion" or (
        step.action == "marker_motion" and step.goal.get("target") != "work_pose"
    )


def retreat_steps(plan: list[Step], failed_index: int) -> list[Step]:
    """After a failure at plan[failed_index] that left the gripper empty (`RETREAT_AFTER`): open,
    back out of the nest or pocket the last arm motion went into, tuck.

    Why: the arm reached its last target, so the way it came in is clear; left there it stands in
    the nest, in front of the marker the next task must see first (seen: MARKER_NOT_FOUND after a
    plate was taken away mid-GetLabware). Empty when no arm motion ran, or the last one tucked it.
    """
    arm_steps = [step for step in plan[: failed_index + 1] if _moves_the_arm(step)]
    last = arm_steps[-1] if arm_steps else None
    if last is None or last.goal.get("motion_name") == "Tuck":
        return []
    arm = last.goal.get("arm", "")
    back_out = way_out(last)
    return [
        Step("gripper", {"command": "open", "arm": arm}, "releasing after the failure"),
        *([back_out] if back_out is not None else []),
        Step("play_motion", {"motion_name": "Tuck", "arm": arm}, "arm tucked"),
    ]
