"""`{world-schema}`: the world file's keys, generated from its one definition.

Renders `lab_description.world_schema.json_schema()` (the pydantic models' JSON Schema, the same the
editors use) as one table per object: key, type, whether it is required, its default, its range and
its description. The page follows the code; a key added there appears here on the next build.
"""

from __future__ import annotations

from typing import Any

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective
from tables import table

_RANGE_WORDS = {
    "minimum": ">=",
    "maximum": "<=",
    "exclusiveMinimum": ">",
    "exclusiveMaximum": "<",
    "minLength": "length >=",
    "maxLength": "length <=",
    "minItems": "items >=",
    "maxItems": "items <=",
}


def _ref_name(ref: str) -> str:
    return ref.rsplit("/", 1)[-1]


def _type(spec: dict[str, Any]) -> str:
    if "$ref" in spec:
        return _ref_name(spec["$ref"])
    if "anyOf" in spec:
        return " or ".join(_type(option) for option in spec["anyOf"])
    if "allOf" in spec:
        return " and ".join(_type(option) for option in spec["allOf"])
    if "enum" in spec:
        return "one of " + ", ".join(repr(value) for value in spec["enum"])
    if "const" in spec:
        return repr(spec["const"])
    kind = spec.get("type", "any")
    if kind == "array":
        if "prefixItems" in spec:
            return "[" + ", ".join(_type(item) for item in spec["prefixItems"]) + "]"
        return f"list of {_type(spec.get('items', {}))}"
    if kind == "object" and "additionalProperties" in spec:
        return f"map of name to {_type(spec['additionalProperties'])}"
    return str(kind)


def _range(spec: dict[str, Any]) -> str:
    parts = [f"{word} {spec[key]}" for key, word in _RANGE_WORDS.items() if key in spec]
    if "not" in spec and "enum" in spec["not"]:
        parts.append("not " + ", ".join(str(value) for value in spec["not"]["enum"]))
    for option in spec.get("anyOf", []):
        inner = _range(option)
        if inner:
            parts.append(inner)
    return "; ".join(parts)


def _object_table(properties: dict[str, Any], required: set[str]) -> nodes.table:
    rows = [
        (
            key,
            _type(spec),
            "yes" if key in required else "",
            repr(spec["default"]) if "default" in spec else "",
            _range(spec),
            spec.get("description", ""),
        )
        for key, spec in properties.items()
    ]
    return table(
        ("key", "type", "required", "default", "range", "description"), (14, 18, 8, 10, 14, 36), rows
    )


class WorldSchemaReference(SphinxDirective):
    has_content = False

    def run(self) -> list[nodes.Node]:
        from lab_description.world_schema import json_schema

        schema = json_schema()
        self.env.note_dependency(str(self.env.srcdir.parent / "tiago_sim" / "lab" / "world_schema.py"))
        objects = [(schema.get("title", "the file"), schema)]
        objects += sorted(schema.get("$defs", {}).items())
        result: list[nodes.Node] = []
        for name, spec in objects:
            if "properties" not in spec:
                continue
            box = nodes.container(ids=[nodes.make_id("world " + name)])
            box += nodes.rubric(text=name)
            if spec.get("description"):
                box += nodes.paragraph(text=spec["description"])
            box += _object_table(spec["properties"], set(spec.get("required", [])))
            result.append(box)
        return result


def setup(app: Sphinx) -> dict[str, object]:
    app.add_directive("world-schema", WorldSchemaReference)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
