"""A generated layout as a world file on disk: YAML with a header that says where it came from.

Why a module: the file is what a failed trial leaves next to its report, so it must run as it is
with `sila-labware demo --world FILE` and tell a reader how to make it again. Any thread.
"""

from __future__ import annotations

from pathlib import Path

import yaml

from lab_description.world_schema import SCHEMA_FILE
from tiago_sim.layouts.furnish import furnish
from tiago_sim.layouts.generator import generate_layout


def layout_yaml(seed: int) -> str:
    """The world file text of the random layout `seed`."""
    header = (
        f"# yaml-language-server: $schema={SCHEMA_FILE}\n"
        f"# Random layout, seed {seed}: `sila-labware bench --save-layout {seed} FILE` writes it again;\n"
        '# run it with `sila-labware demo --world FILE`. Ranges: README, "Random layouts".\n'
    )
    return header + yaml.safe_dump(generate_layout(seed), sort_keys=False, default_flow_style=None, width=100)


def furnished_yaml(base: Path, seed: int) -> str:
    """The world file text of `base` with the random obstacles of `seed`."""
    header = (
        f"# yaml-language-server: $schema={SCHEMA_FILE}\n"
        f"# {base} with random obstacles, seed {seed}: `sila-labware bench --random-obstacles\n"
        f"# --world {base} --save-layout {seed} FILE` writes it again; run it with\n"
        "# `sila-labware demo --world FILE`.\n"
    )
    raw = furnish(yaml.safe_load(Path(base).read_text()), seed, str(base))
    return header + yaml.safe_dump(raw, sort_keys=False, default_flow_style=None, width=100)


def write_layout(seed: int, path: Path, furnish_base: Path | None = None) -> Path:
    """The random layout `seed`, or with `furnish_base` that world with the random obstacles of `seed`."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(layout_yaml(seed) if furnish_base is None else furnished_yaml(furnish_base, seed))
    return path
