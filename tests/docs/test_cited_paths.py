"""Every repository path the documentation cites exists, and every link between pages resolves.

A cited path is a code span that looks like one: `lab_description/world.py`, `tests/examples/`,
`sila_labware/servers/*/feature_implementations/` (a glob), or a shorter path such as
`physics/seating.py` that must end some path of the repository; a bare `something.py` must name a
file somewhere in it. ROS names (`/map`, `nav_msgs/Path`), SiLA identifiers and nests
(`station_a/1`) have no file extension and are not paths.
"""

from __future__ import annotations

import importlib.util
import re
from functools import lru_cache
from pathlib import Path

import pytest

from tests.docs.pages import REPOSITORY, name, pages, prose

CODE_SPAN = re.compile(r"`([^`\n]+)`")
LINK = re.compile(r"\]\(([^)\s]+)\)")
PATH = re.compile(r"^[\w.*-]+(/[\w.*-]+)*/?$")
EXTENSIONS = (".py", ".yaml", ".yml", ".xml", ".json", ".toml", ".msg", ".action", ".srv", ".md", ".txt")


def _pictures_drawn_at_build() -> dict[str, str]:
    """docs/_ext/command_output.py's PICTURES (world file -> picture), read from the extension."""
    extension = REPOSITORY / "docs" / "_ext" / "command_output.py"
    spec = importlib.util.spec_from_file_location("command_output", extension)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.PICTURES


GENERATED = REPOSITORY / "docs" / "_generated"
DRAWN_AT_BUILD = frozenset(_pictures_drawn_at_build().values())
"""The pictures docs/_ext/command_output.py draws into GENERATED when the site is built."""
SKIP = {".venv", ".git", "build", "_generated", "__pycache__", ".pytest_cache", ".ruff_cache"}


@lru_cache(maxsize=1)
def repository_paths() -> frozenset[str]:
    found = set()
    for path in REPOSITORY.rglob("*"):
        relative = path.relative_to(REPOSITORY)
        if SKIP.intersection(relative.parts):
            continue
        found.add(str(relative) + ("/" if path.is_dir() else ""))
    return frozenset(found)


def top_level() -> set[str]:
    return {p.rstrip("/") for p in repository_paths() if "/" not in p.rstrip("/")}


def cited_paths(text: str) -> list[str]:
    cited = []
    for span in CODE_SPAN.findall(text):
        token = span.strip().split()[0] if span.strip() else ""
        if len(span.split()) != 1 or not PATH.match(token):
            continue
        if "/" in token.rstrip("/") and (token.split("/")[0] in top_level() or token.endswith(EXTENSIONS)):
            cited.append(token)
        elif "/" not in token and token.endswith(".py"):
            cited.append(token)
    return cited


def exists(token: str) -> bool:
    if "/" not in token:  # a bare file name: somewhere in the repository
        return any(p == token or p.endswith("/" + token) for p in repository_paths())
    if token.split("/")[0] in top_level():
        return any(REPOSITORY.glob(token.rstrip("/"))) if "*" in token else (REPOSITORY / token).exists()
    return any(
        p.endswith("/" + token) or p.endswith("/" + token.rstrip("/") + "/") for p in repository_paths()
    )


@pytest.mark.parametrize("page", pages(), ids=name)
def test_every_cited_repository_path_exists(page: Path) -> None:
    missing = sorted({token for token in cited_paths(prose(page)) if not exists(token)})
    assert missing == [], f"{name(page)} cites paths that do not exist: {missing}"


@pytest.mark.parametrize("page", pages(), ids=name)
def test_every_link_to_a_file_resolves(page: Path) -> None:
    broken = []
    for target in LINK.findall(prose(page)):
        if re.match(r"^[a-z]+://|^mailto:|^#", target):
            continue
        path = (page.parent / target.split("#", 1)[0]).resolve()
        if path.parent == GENERATED:  # drawn by the build (test_docs_build), not committed
            if path.name not in DRAWN_AT_BUILD:
                broken.append(target)
        elif not path.exists():
            broken.append(target)
    assert broken == [], f"{name(page)} links to files that do not exist: {broken}"


def test_the_rule_sees_paths_and_not_names() -> None:
    text = (
        "`lab_description/world.py`, `/map`, `nav_msgs/Path`, `station_a/1`, `seating.py`, `serve --pace 1`"
    )
    assert cited_paths(text) == ["lab_description/world.py", "seating.py"]
    assert not exists("tests/tiago_sim/physics/test_scene_floor.py")
    assert exists("physics/seating.py") and exists("sila_labware/servers/*/feature_implementations/")
