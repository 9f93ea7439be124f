"""`{sila-feature} FILE` and `{sila-errors}`: the SiLA features, generated from their definitions.

`{sila-feature}` renders one Feature Definition (FDL, `features/*.sila.xml`): its identifier,
description, and a table of its commands (observable or not) and properties with their
descriptions and defined execution errors. `{sila-errors}` lists every defined execution error of
every feature in `features/` with the feature that defines it and its description. Both read the
XML the servers are generated from, so the page is the servers' own definition.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ElementTree
from pathlib import Path

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective
from tables import table

FEATURES = Path(__file__).resolve().parents[2] / "features"
NS = {"s": "http://www.sila-standard.org"}


def _text(element: ElementTree.Element | None, tag: str) -> str:
    found = None if element is None else element.find(f"s:{tag}", NS)
    if found is None or found.text is None:
        return ""
    return re.sub(r"\s+", " ", found.text).strip()


def _errors_of(element: ElementTree.Element) -> list[str]:
    return [e.text.strip() for e in element.findall("s:DefinedExecutionErrors/s:Identifier", NS) if e.text]


class SilaFeature(SphinxDirective):
    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        path = FEATURES / self.arguments[0]
        self.env.note_dependency(str(path))
        root = ElementTree.parse(path).getroot()
        originator, category = root.get("Originator", ""), root.get("Category", "")
        identifier = _text(root, "Identifier")
        version = root.get("FeatureVersion", "1.0").split(".")[0]
        qualified = f"{originator}/{category}/{identifier}/v{version}"
        box = nodes.container(ids=[nodes.make_id("feature " + identifier)])
        box += nodes.rubric(text=_text(root, "DisplayName") or identifier)
        box += nodes.paragraph("", "", nodes.literal(text=qualified))
        box += nodes.paragraph(text=_text(root, "Description"))
        rows = []
        for command in root.findall("s:Command", NS):
            kind = "observable command" if _text(command, "Observable") == "Yes" else "command"
            errors = ", ".join(_errors_of(command))
            rows.append((_text(command, "Identifier"), kind, _text(command, "Description"), errors))
        for prop in root.findall("s:Property", NS):
            kind = "observable property" if _text(prop, "Observable") == "Yes" else "property"
            rows.append(
                (_text(prop, "Identifier"), kind, _text(prop, "Description"), ", ".join(_errors_of(prop)))
            )
        if rows:
            box += table(("name", "kind", "what it does", "defined errors"), (16, 12, 52, 20), rows)
        return [box]


class SilaErrors(SphinxDirective):
    def run(self) -> list[nodes.Node]:
        rows = []
        for path in sorted(FEATURES.glob("*.sila.xml")):
            self.env.note_dependency(str(path))
            root = ElementTree.parse(path).getroot()
            for error in root.findall("s:DefinedExecutionError", NS):
                rows.append(
                    (_text(error, "Identifier"), _text(root, "Identifier"), _text(error, "Description"))
                )
        return [table(("error", "feature", "when"), (22, 22, 56), rows)]


def setup(app: Sphinx) -> dict[str, object]:
    app.add_directive("sila-feature", SilaFeature)
    app.add_directive("sila-errors", SilaErrors)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
