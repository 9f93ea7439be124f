"""The plates a robot knows by name, and where its sensors put them: the inventory's rules, pure.

Why one inventory, and why here: a scheduler names its plates (the standard's LabwareUniqueID), a
sensor says where a plate is (presence) and, where a reader can, what its label reads. The two
are different things: a scheduler cannot know the labels, and a lab's ids need not be barcodes.
So the inventory keeps the scheduler's name for a plate and settles *where* it is on presence
alone; a label is only evidence of identity (the same plate seen elsewhere after a restart) and a
mismatch between a label and a name is noted, never taken for a lost plate.

The robot side holds one `LabwareBook` (the task sequencer, which runs every transfer whichever
door it came through) and publishes its records; the SiLA servers and the Bluesky device read
those. This module has no threads, no ROS and no I/O besides the JSON form of the records.

Rules:
- A goal names the plate at its source (`name_plate`): the scheduler's id replaces whatever
  name the plate had; without one, the plate keeps its name, else takes its label.
- A transfer settles the plate on the holder whose sensor shows it (`move`).
- Between transfers the book follows the sensors (`reconcile`): a plate whose label is read where
  a record with that label is not moves there under its name; a record whose holder's sensor sees
  no plate becomes unknown; a plate nobody named takes its label as its name (an unread one
  stays unnamed until a goal names it).
"""

from __future__ import annotations

import json
import logging
from collections.abc import Collection, Iterable, Sequence
from dataclasses import dataclass, replace

from labware_model.holders import GRIPPER, UNKNOWN, Location, location_text, parse_location
from labware_model.readings import HotelSlotReading, NestReading

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class LabwareRecord:
    """One named plate: its name (the scheduler's id, else its label), its type, where it is (a
    nest, a hotel slot, the gripper or `UNKNOWN`), and the label a reader last read off it (""
    if none was ever read)."""

    labware_id: str
    labware_type: str
    location: Location
    label: str = ""

    @property
    def note(self) -> str:
        """For people: a label that reads other than the name ("" when they agree)."""
        return label_note(self.label, self.labware_id)


@dataclass(frozen=True)
class SensedPlate:
    """A holder whose presence sensor sees a plate, with the label its reader read ("" if none)."""

    holder: Location
    label: str = ""
    labware_type: str = ""


def sensed_plates(
    hotel: Iterable[HotelSlotReading], holding: bool, held_label: str, nests: Iterable[NestReading]
) -> tuple[SensedPlate, ...]:
    """Every holder whose sensor sees a plate: hotel slots, the gripper, station nests."""
    seen = [SensedPlate(r.slot, r.labware_id, r.labware_type) for r in hotel if r.occupied]
    if holding or held_label:
        seen.append(SensedPlate(GRIPPER, held_label))
    seen += [SensedPlate(r.nest, r.labware_id) for r in nests if r.occupied]
    return tuple(seen)


def label_note(label: str, name: str) -> str:
    """The note a record carries when its label reads other than its name ("" when they agree)."""
    if label and name and label != name:
        return f"its label reads {label!r}, not {name!r}"
    return ""


class NameTaken(ValueError):
    """A goal names a plate with the name of another plate the book places elsewhere."""


class LabwareBook:
    """Name -> record, with the rules above. Not thread-safe: its owner uses it on one thread."""

    def __init__(self, records: Iterable[LabwareRecord] = ()) -> None:
        self._records: dict[str, LabwareRecord] = {record.labware_id: record for record in records}

    def records(self) -> tuple[LabwareRecord, ...]:
        return tuple(self._records[name] for name in sorted(self._records))

    def get(self, name: str) -> LabwareRecord | None:
        return self._records.get(name)

    def at(self, holder: Location) -> LabwareRecord | None:
        """The record placed at `holder` (never for UNKNOWN: many plates can be lost)."""
        if holder == UNKNOWN:
            return None
        return next((r for r in self._records.values() if r.location == holder), None)

    def name_plate(self, holder: Location, name: str, labware_type: str, label: str) -> LabwareRecord | None:
        """Name the plate at `holder` as a goal starts: `name` (the goal's id) if given, else the
        name it has, else its `label`. Returns its record (None for an unread plate nobody named).
        Raises NameTaken when another plate of that name is at a known place other than `holder`."""
        current = self.at(holder)
        chosen = name or (current.labware_id if current else "") or label
        if not chosen:
            return None
        other = self._records.get(chosen)
        if other is not None and other is not current and other.location not in (holder, UNKNOWN):
            raise NameTaken(f"labware {chosen!r} is at {other.location}, not at {holder}")
        if current is not None and current.labware_id != chosen:
            del self._records[current.labware_id]
            logger.info("the plate at %s, %r until now, is named %r", holder, current.labware_id, chosen)
        known_label = label or (current.label if current else "")
        kept_type = labware_type or (current.labware_type if current else "")
        record = LabwareRecord(chosen, kept_type, holder, known_label)
        if record.note:
            logger.warning("labware %s at %s: %s", chosen, holder, record.note)
        self._records[chosen] = record
        return record

    def move(self, name: str, location: Location) -> bool:
        """Put the named plate at `location`; True if that changed anything."""
        record = self._records.get(name)
        if record is None or record.location == location:
            return False
        displaced = self.at(location)
        if displaced is not None:  # a holder holds one plate: the record there was stale
            self._records[displaced.labware_id] = replace(displaced, location=UNKNOWN)
        self._records[name] = replace(record, location=location)
        return True

    def settle(
        self,
        name: str,
        candidates: Sequence[Location],
        sensed: Sequence[SensedPlate],
        unsensed: Location | None = None,
    ) -> bool:
        """After a transfer: the named plate is on the first of `candidates` (the transfer's
        destination, the gripper, its source) whose sensor sees a plate; else at `unsensed`, a
        holder with no sensor where the transfer's checked steps put it; else unknown. True if that
        changed anything."""
        occupied = {plate.holder for plate in sensed}
        found = next((holder for holder in candidates if holder in occupied), unsensed)
        return self.move(name, found if found is not None else UNKNOWN)

    def reconcile(self, sensed: Sequence[SensedPlate], sensed_holders: Collection[Location]) -> bool:
        """Follow the sensors between transfers (see the module's rules). `sensed_holders`: every
        holder that has a presence sensor; a record elsewhere is left as it is. True if it changed."""
        before = self.records()
        confirmed: set[str] = set()
        for plate in sensed:
            record = self._by_label(plate.label) if plate.label else None
            if record is None:
                record = self.at(plate.holder)
                if record is not None and plate.label and record.label and record.label != plate.label:
                    record = None  # another plate than the one recorded here
            if record is None and plate.label and plate.label not in self._records:
                record = LabwareRecord(plate.label, plate.labware_type, plate.holder, plate.label)
            if record is None:
                continue  # unread and unnamed, or its label is another plate's name: a goal names it
            label = plate.label or record.label
            self._records[record.labware_id] = replace(record, location=plate.holder, label=label)
            confirmed.add(record.labware_id)
        for name, record in list(self._records.items()):
            if name not in confirmed and record.location in sensed_holders:
                self._records[name] = replace(record, location=UNKNOWN)
        return self.records() != before

    def _by_label(self, label: str) -> LabwareRecord | None:
        return next((r for r in self._records.values() if r.label == label), None)

    # --- the JSON form, for the robot side's file that outlives a restart ---

    def to_json(self) -> str:
        return json.dumps(
            [
                {
                    "labware_id": r.labware_id,
                    "labware_type": r.labware_type,
                    "location": location_text(r.location),
                    "label": r.label,
                }
                for r in self.records()
            ],
            indent=1,
        )

    @classmethod
    def from_json(cls, text: str) -> LabwareBook:
        """The book `to_json` wrote; raises ValueError for anything else."""
        try:
            items = json.loads(text)
            records = [
                LabwareRecord(
                    str(item["labware_id"]),
                    str(item["labware_type"]),
                    parse_location(str(item["location"])),
                    str(item.get("label", "")),
                )
                for item in items
            ]
        except (TypeError, KeyError, json.JSONDecodeError) as error:
            raise ValueError(f"not an inventory file: {error}") from error
        return cls(records)
