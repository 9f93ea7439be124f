"""ROS 2 interface definitions (.msg / .srv / .action lines) read into fields and constants.

Why: our builds of the robot's interfaces that have no wheel (robot_port/ros_interfaces) must be
identical on the wire to the robot's distribution's. The tests compare three things that must
agree: the upstream definitions as recorded with their commits (robot_port/upstream_interfaces.yaml),
our source files, and the Python types our build produced (rosidl's own introspection). This module
turns definition lines into one comparable form, and a built type into the same form.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

PRIMITIVES = {
    "bool": "boolean",
    "byte": "octet",
    "char": "uint8",
    "float32": "float",
    "float64": "double",
    "int8": "int8",
    "uint8": "uint8",
    "int16": "int16",
    "uint16": "uint16",
    "int32": "int32",
    "uint32": "uint32",
    "int64": "int64",
    "uint64": "uint64",
    "string": "string",
    "wstring": "wstring",
}
_ARRAY = re.compile(r"^(?P<base>[^\[]+)(?:\[(?P<bound>[^\]]*)\])?$")
_LINE = re.compile(r"^(?P<type>\S+)\s+(?P<name>[A-Za-z_][A-Za-z0-9_]*)\s*(?P<rest>.*)$")


@dataclass(frozen=True)
class Definition:
    """One message (or one section of a service or action): fields in order and constants."""

    fields: tuple[tuple[str, str, str], ...]  # (name, rosidl type, default as written or "")
    constants: tuple[tuple[str, str, str], ...]  # (name, rosidl type, value as written)


def rosidl_type(written: str, package: str) -> str:
    """The type as rosidl's Python introspection spells it (`get_fields_and_field_types`)."""
    match = _ARRAY.match(written)
    if match is None:
        raise ValueError(f"not a field type: {written!r}")
    base, bound = match["base"], match["bound"]
    if base.startswith("string<="):
        element = f"string<{base.removeprefix('string<=')}>"
    elif base in PRIMITIVES:
        element = PRIMITIVES[base]
    else:
        element = base if "/" in base else f"{package}/{base}"
    if bound is None:
        return element
    if bound == "":
        return f"sequence<{element}>"
    if bound.startswith("<="):
        return f"sequence<{element}, {bound[2:]}>"
    return f"{element}[{bound}]"


def parse_lines(lines: list[str], package: str) -> Definition:
    """Fields and constants of one section, comments and blank lines dropped."""
    fields, constants = [], []
    for raw in lines:
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        match = _LINE.match(line)
        if match is None:
            raise ValueError(f"not a definition line: {raw!r}")
        kind, name, rest = rosidl_type(match["type"], package), match["name"], match["rest"].strip()
        if rest.startswith("="):
            constants.append((name, kind, rest[1:].strip()))
        elif "=" in name:
            raise ValueError(f"unexpected line: {raw!r}")
        else:
            fields.append((name, kind, rest))
    return Definition(tuple(fields), tuple(constants))


def parse_file_text(text: str, package: str) -> list[Definition]:
    """Each `---`-separated section of a .msg, .srv or .action file."""
    sections: list[list[str]] = [[]]
    for line in text.splitlines():
        if line.strip() == "---":
            sections.append([])
        else:
            sections[-1].append(line)
    return [parse_lines(section, package) for section in sections]


def built_definition(message_class: Any) -> Definition:
    """Fields (in order, as rosidl generated their types) and constants of a built Python type.
    Constants' values, and defaults, are Python values here (see `written_value`)."""
    prepared = type(message_class).__prepare__(message_class.__name__, ())  # constants and defaults
    suffix = "__DEFAULT"
    defaults = {k.removesuffix(suffix).lower(): v for k, v in prepared.items() if k.endswith(suffix)}
    fields = tuple(
        (name, kind, repr(defaults[name]) if name in defaults else "")
        for name, kind in message_class.get_fields_and_field_types().items()
    )
    constants = tuple(
        (name, "", repr(value)) for name, value in prepared.items() if not name.endswith(suffix)
    )
    return Definition(fields, constants)


def written_value(kind: str, written: str) -> str:
    """A default or constant as written in a definition, as the repr of the Python value rosidl gives it."""
    if not written:
        return ""
    if kind == "boolean":
        return repr(written.strip().lower() in ("true", "1"))
    if kind in ("float", "double"):
        return repr(float(written))
    if kind.startswith("string") or kind.startswith("wstring"):
        text = written.strip()
        return repr(text[1:-1] if text[:1] in "'\"" and text[-1:] == text[:1] else text)
    return repr(int(written))


def as_built(definition: Definition) -> Definition:
    """A parsed definition in the form `built_definition` gives: values as Python reprs, no types on
    constants (rosidl keeps a constant's value, not its type)."""
    return Definition(
        tuple((name, kind, written_value(kind, value)) for name, kind, value in definition.fields),
        tuple((name, "", written_value(kind, value)) for name, kind, value in definition.constants),
    )
