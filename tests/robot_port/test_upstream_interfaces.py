"""Our builds of the robot's interfaces that have no wheel are the robot's, field for field.

Why: a goal to a TIAGo++'s controllers or to Nav2 only reaches them when both ends agree on the
type's name and layout; a field left out, reordered or typed differently is a type nobody serves.
The upstream table (robot_port/upstream_interfaces.yaml) records each definition as the robot's
distribution has it, with the repository and commit it was read from; our source files and the
Python types the set-up built from them must both match it, and the docs must cite each source.
"""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest
import yaml

from tests.helpers.interface_definitions import as_built, built_definition, parse_file_text, parse_lines

REPOSITORY = Path(__file__).resolve().parents[2]
TABLE = yaml.safe_load((REPOSITORY / "robot_port" / "upstream_interfaces.yaml").read_text())
PACKAGES = REPOSITORY / "robot_port" / "ros_interfaces"
DOCS_PAGE = REPOSITORY / "docs" / "reference" / "robot-interfaces.md"
SECTIONS = {"msg": ("message",), "srv": ("request", "response"), "action": ("goal", "result", "feedback")}
PYTHON_PARTS = {"message": None, "request": "Request", "response": "Response"}
PYTHON_PARTS |= {"goal": "Goal", "result": "Result", "feedback": "Feedback"}


def _parts(name: str) -> tuple[str, str, str]:
    package, kind, type_name = name.split("/")
    return package, kind, type_name


def _upstream_lines(name: str, section: str) -> list[str]:
    """A section's upstream lines less those the table says our build leaves out (with a reason)."""
    left_out = TABLE[name].get("left_out", {})
    assert not left_out or left_out.get("why"), f"{name}: lines left out without a reason"
    return [line for line in TABLE[name][section] if line not in left_out.get(section, [])]


@pytest.mark.parametrize("name", sorted(TABLE))
def test_our_source_file_is_the_upstream_definition(name: str) -> None:
    package, kind, type_name = _parts(name)
    ours = parse_file_text((PACKAGES / package / kind / f"{type_name}.{kind}").read_text(), package)
    upstream = [parse_lines(_upstream_lines(name, section), package) for section in SECTIONS[kind]]
    assert ours == upstream


@pytest.mark.parametrize("name", sorted(TABLE))
def test_the_built_type_is_the_upstream_definition(name: str) -> None:
    package, kind, type_name = _parts(name)
    built = getattr(importlib.import_module(f"{package}.{kind}"), type_name)
    for section in SECTIONS[kind]:
        part = PYTHON_PARTS[section]
        message_class = built if part is None else getattr(built, part)
        expected = as_built(parse_lines(_upstream_lines(name, section), package))
        assert built_definition(message_class) == expected, f"{name}: {section}"


def test_every_definition_we_build_is_in_the_upstream_table() -> None:
    ours = {
        f"{path.parts[-3]}/{path.parts[-2]}/{path.stem}"
        for path in PACKAGES.glob("*/*/*")
        if path.suffix.lstrip(".") in SECTIONS
    }
    assert ours == set(TABLE)


def test_each_upstream_source_is_cited_in_the_docs() -> None:
    page = DOCS_PAGE.read_text()
    for name, entry in TABLE.items():
        assert entry["source"] in page, f"{name}: {entry['source']} not cited on {DOCS_PAGE.name}"
        assert name in page


def test_a_differing_field_is_noticed() -> None:
    """The comparison sees a type, an order, a default and a constant's value (the test can fail)."""
    base = parse_lines(["uint16 A=1", "string name", "bool flag True"], "p")
    for changed in (
        ["uint16 A=2", "string name", "bool flag True"],
        ["uint16 A=1", "bool flag True", "string name"],
        ["uint16 A=1", "string name", "bool flag False"],
        ["uint16 A=1", "string[] name", "bool flag True"],
    ):
        assert parse_lines(changed, "p") != base
        assert as_built(parse_lines(changed, "p")) != as_built(base)
