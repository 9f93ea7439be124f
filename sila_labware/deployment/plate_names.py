"""The names the world file gives its plates, and where each starts: the demo's words for them.

Why: a scheduler names its plates; the robot reads a plate's label only where a lab has added
barcode readers. The demo stands for a scheduler: where no reader read the source's label, it
names the plate as the lab's own description does (the world file's `plates`). The robot side
validates the whole file; this reads that one list. Pure; safe on any thread.
"""

from __future__ import annotations

from pathlib import Path

import yaml

from labware_model.holders import HotelSlot, Nest


def plate_named_at(world: Path, nest: Nest) -> str:
    """The id of the world file's plate that starts in `nest` ("" when it names none there)."""
    return next((name for name, holder in plates_at_start(world).items() if holder == nest), "")


def plates_at_start(world: Path) -> dict[str, Nest | HotelSlot]:
    """Every plate the world file names, and the nest or hotel slot it starts in (empty: no list)."""
    try:
        data = yaml.safe_load(world.read_text())
    except (OSError, yaml.YAMLError):
        return {}
    plates = data.get("plates") if isinstance(data, dict) else None
    found: dict[str, Nest | HotelSlot] = {}
    for plate in plates if isinstance(plates, list) else []:
        if not isinstance(plate, dict) or not plate.get("id"):
            continue
        if plate.get("hotel_slot") is not None:
            found[str(plate["id"])] = HotelSlot(int(plate["hotel_slot"]))
        elif plate.get("station") is not None and plate.get("sub_position") is not None:
            found[str(plate["id"])] = Nest(str(plate["station"]), int(plate["sub_position"]))
    return found
