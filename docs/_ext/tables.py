"""One docutils table for the reference pages the extensions generate (CLI, SiLA features, world schema).

Why one: each generated page shows rows of text under titles; the first column names a thing
(an option, a command, a key) and is set as code.
"""

from __future__ import annotations

from collections.abc import Sequence

from docutils import nodes


def _entry(text: str, literal: bool) -> nodes.entry:
    inner = nodes.literal(text=text) if literal and text else nodes.Text(text)
    return nodes.entry("", nodes.paragraph("", "", inner))


def table(titles: Sequence[str], widths: Sequence[int], rows: Sequence[Sequence[str]]) -> nodes.table:
    """A table of `rows` under `titles`, columns `widths` wide (relative); the first column as code."""
    built = nodes.table()
    group = nodes.tgroup(cols=len(titles))
    built += group
    for width in widths:
        group += nodes.colspec(colwidth=width)
    head = nodes.thead()
    group += head
    header = nodes.row()
    for title in titles:
        header += _entry(title, literal=False)
    head += header
    body = nodes.tbody()
    group += body
    for cells in rows:
        row = nodes.row()
        for index, cell in enumerate(cells):
            row += _entry(cell, literal=index == 0)
        body += row
    return built
