"""A generated layout as a world file on disk: YAML with a header that says where it came from.

Why a module: the file is what a failed trial leaves next to its report, so it must run as it is
with `sila-labware demo --world FILE` and tell a reader how to make it again. Any thread.
"""

from __future__ import annotations

from pathlib import Path

import yaml

from tiago_sim.lab.world_schema import SCHEMA_FILE
from tiago_sim.layouts.generator import generate_layout


def layout_yaml(seed: int) -> str:
    """The world file text of the random layout `seed`."""
    header = (
        f"# yaml-language-server: $schema={SCHEMA_FILE}\n"
        f"# Random layout, seed {seed}: `sila-labware bench --save-layout {seed} FILE` writes it again;\n"
        '# run it with `sila-labware demo --world FILE`. Ranges: README, "Random layouts".\n'
    )
    return header + yaml.safe_dump(generate_layout(seed), sort_keys=False, default_flow_style=None, width=100)


def write_layout(seed: int, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(layout_yaml(seed))
    return path
