"""The wheel carries the program, not campaign output.

Campaign reports (summaries, charts, run pictures, failed trials' world files) belong outside the
package: on the benchmarks pages as figures, in the git history as files. setuptools finds
namespace packages (any folder under an included top-level package) and takes every `*.yaml` as
package data, so a report folder inside a package would ship in the wheel. These tests compute what
setuptools packages, as `pyproject.toml` configures it, and look for such output there.
"""

from __future__ import annotations

import re

from setuptools import find_namespace_packages

from tests.docs.pages import REPOSITORY

CAMPAIGN_OUTPUT = re.compile(
    r"^(summary\.json|summary\.txt|trials\.jsonl|success_by_cause\.png|time_per_phase\.png"
    r"|run_strip\.png|run\.gif|layout_\d+\.yaml|soak_.*\.json)$"
)


def packaged() -> list[str]:
    """The packages the wheel holds: `[tool.setuptools.packages.find]` of pyproject.toml."""
    text = (REPOSITORY / "pyproject.toml").read_text()
    section = text.split("[tool.setuptools.packages.find]", 1)[1].split("\n[", 1)[0]
    include = re.findall(r'"([^"]+)"', section.split("include", 1)[1].split("]", 1)[0])
    assert include, "pyproject.toml names no packages to include"
    return find_namespace_packages(where=str(REPOSITORY), include=include)


def test_no_docs_folder_is_packaged() -> None:
    packages = packaged()
    assert "sila_labware" in packages and "lab_description.worlds" in packages
    assert [p for p in packages if "docs" in p.split(".")] == []


def test_no_package_holds_campaign_output() -> None:
    found = [
        str(path.relative_to(REPOSITORY))
        for package in packaged()
        for path in (REPOSITORY / package.replace(".", "/")).iterdir()
        if path.is_file() and CAMPAIGN_OUTPUT.match(path.name)
    ]
    assert found == [], "campaign output inside a package ships in the wheel: " + ", ".join(found)


def test_the_rule_recognises_campaign_output() -> None:
    assert CAMPAIGN_OUTPUT.match("layout_83075.yaml") and CAMPAIGN_OUTPUT.match("summary.json")
    assert not CAMPAIGN_OUTPUT.match("default.yaml") and not CAMPAIGN_OUTPUT.match("sequencer.yaml")
