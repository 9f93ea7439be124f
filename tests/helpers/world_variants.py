"""The bundled default lab with one more plate, or other changes, written where a test wants it.

Why: several tests need the default lab with a plate here or a switch there; one helper keeps
them the same lab and writes what each changes in one line.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from lab_description.world import DEFAULT_WORLD


def default_world_with(
    path: Path, plates: dict[str, tuple[str, int]] | None = None, **top_level: Any
) -> Path:
    """The default world with extra `plates` (id -> (station, sub_position), the first plate's
    type) and top-level keys replaced, written to `path`."""
    world = yaml.safe_load(DEFAULT_WORLD.read_text())
    first = world["plates"][0]
    for labware_id, (station, sub_position) in (plates or {}).items():
        world["plates"].append({**first, "id": labware_id, "station": station, "sub_position": sub_position})
    world.update(top_level)
    path.write_text(yaml.safe_dump(world))
    return path
