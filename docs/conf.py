"""Sphinx configuration of the documentation site (`./run docs`; tests/docs builds it with -W)."""

from __future__ import annotations

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
REPOSITORY = DOCS.parent
sys.path.insert(0, str(DOCS / "_ext"))
sys.path.insert(0, str(REPOSITORY))

project = "sila-labware"
author = "the sila-labware authors"
copyright = "the sila-labware authors"  # noqa: A001 (Sphinx's name)

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "cli_reference",
    "world_schema_reference",
    "command_output",
    "sila_features",
]

source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_generated/*.txt", "README.md"]
myst_enable_extensions = ["colon_fence", "deflist"]
myst_heading_anchors = 3
html_theme = "furo"
html_title = "sila-labware"
templates_path: list[str] = []

# The client's signatures, as its users call them; its docstrings are prose, not reST fields.
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "show-inheritance": False}
# The docstrings cite the code with Markdown backticks, which reST reads as the default role.
default_role = "literal"
nitpicky = False
