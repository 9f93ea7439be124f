"""The name the world file gives the plate that starts in a nest: the demo's word for its plate.

Why: a scheduler names its plates; the robot reads a plate's label only where a lab has added
barcode readers. The demo stands for a scheduler: where no reader read the source's label, it
names the plate as the lab's own description does (the world file's `plates`). The robot side
validates the whole file; this reads that one list. Pure; safe on any thread.
"""

from __future__ import annotations

from pathlib import Path

import yaml

from labware_model.holders import Nest


def plate_named_at(world: Path, nest: Nest) -> str:
    """The id of the world file's plate that starts in `nest` ("" when it names none there)."""
    try:
        data = yaml.safe_load(world.read_text())
    except (OSError, yaml.YAMLError):
        return ""
    plates = data.get("plates") if isinstance(data, dict) else None
    for plate in plates if isinstance(plates, list) else []:
        if not isinstance(plate, dict):
            continue
        if plate.get("station") == nest.station and plate.get("sub_position") == nest.sub_position:
            return str(plate.get("id", ""))
    return ""
