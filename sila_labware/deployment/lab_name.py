"""The lab's name: what tells two labs' SiLA servers apart on one network.

Why: every lab announced the same server names ("TIAGo Labware Robot", "Station station_a"), so
with two labs on one network (two robots, or parallel CI jobs) discovery by name picked either.
The name comes from `serve --name`, else from the world file's top-level `name` (the robot side
validates the whole file; this reads that one field), else from the world file's name without
its extension. Server names then carry it: "TIAGo Labware Robot (lab 3)", "Station station_a
(lab 3)". Pure; safe on any thread.
"""

from __future__ import annotations

from pathlib import Path

import yaml

MAX_LAB_NAME = 100  # leaves room in SiLA's 255-character server name


def check_lab_name(name: str) -> str:
    """A lab name for server names: 1 to MAX_LAB_NAME printable characters; raises ValueError."""
    if not name.strip():
        raise ValueError("a lab name must not be empty")
    if len(name) > MAX_LAB_NAME:
        raise ValueError(f"a lab name has at most {MAX_LAB_NAME} characters, not {len(name)}")
    if not name.isprintable():
        raise ValueError(f"a lab name must be printable text, not {name!r}")
    return name.strip()


def lab_name_of(world: Path) -> str:
    """The world file's `name`, or its file name without the extension."""
    try:
        data = yaml.safe_load(world.read_text())
    except (OSError, yaml.YAMLError):
        data = None  # the robot side reports the file's problem with its field and line
    name = data.get("name") if isinstance(data, dict) else None
    return check_lab_name(str(name)) if name else world.stem


def robot_server_name(lab: str) -> str:
    return f"TIAGo Labware Robot ({lab})"


def station_server_name(lab: str, station: str) -> str:
    return f"Station {station} ({lab})"
