"""Whether a step's post-condition holds, read from the robot's and the stations' sensors.

Why: a robot command is done when its sensors show its effect, not when its last motion ended (a
plate dropped during a place used to get a successful PutLabware). `unmet` reads one `Expect`
against a /robot_state and a /station_states message and says, in the words of the task's error
message, what the sensor saw instead. Pure; safe on any thread.
"""

from __future__ import annotations

from typing import Any

from labware_model.holders import Gripper, HotelSlot, Nest
from tiago_sim.sequencer.plans import Expect, hotel_slot_state, nest_state


def topic_of(expect: Expect) -> str:
    """Which state topic holds the sensor: "robot" (/robot_state) or "stations" (/station_states)."""
    return "stations" if isinstance(expect.holder, Nest) else "robot"


def unmet(expect: Expect, labware_id: str, robot_state: Any, station_states: Any) -> str:
    """ "" when the sensor of `expect.holder` shows the plate `labware_id` (any plate when the id is
    unknown, or when the holder's reader could not read the label: presence is what the step
    promised; a label read as another plate is not); otherwise what it shows instead."""
    holder = expect.holder
    if isinstance(holder, Gripper):
        present = bool(robot_state.holding or robot_state.held_labware_id)
        return _compare("the gripper", "holds", present, robot_state.held_labware_id, labware_id)
    if isinstance(holder, HotelSlot):
        slot = hotel_slot_state(robot_state, holder)
        present = slot is not None and bool(slot.occupied or slot.labware_id)
        return _compare(
            f"the sensor of {holder}", "sees", present, slot.labware_id if slot else "", labware_id
        )
    reading = nest_state(station_states, holder)
    present = reading is not None and reading.occupied
    return _compare(
        f"the sensor of nest {holder}", "sees", present, reading.labware_id if reading else "", labware_id
    )


def _compare(sensor: str, verb: str, present: bool, seen: str, wanted: str) -> str:
    if not present:
        return f"{sensor} {verb} no plate" if verb == "sees" else f"{sensor} {verb} nothing"
    if seen and wanted and seen != wanted:
        return f"{sensor} {verb} {seen}, not {wanted}"
    return ""
