"""Every code block of the documentation is run, checked, or included from a tested file.

- Python blocks are run, against a simulated lab started for this module: the blocks address the
  lab as `serve` does by default (the robot on port 50052, the stations on the next ports, the CA
  in `./sila-labware-ca.pem`), which this test maps onto the lab's own free ports and CA file.
- Shell blocks hold only commands this project provides or documents: `sila-labware` lines (parsed
  in test_command_lines.py), `./run` verbs, `python -m` modules that exist, example scripts that
  exist, and the plain tools of an install (pip, venv, pytest, cd).
- YAML blocks parse; text blocks are diagrams or output.
- Everything else comes from a directive: `literalinclude` of files the suite runs or loads (the
  examples, world files, interface definitions), `command-output` run at build time, or reference
  generated from the code.
"""

from __future__ import annotations

import importlib.util
import shlex
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

from sila_labware.testing.lab import SimulatedLabSession
from tests.docs.pages import REPOSITORY, Block, blocks, pages
from tests.helpers.sila_stack import DEFAULT_WORLD

ALL_BLOCKS = [block for page in pages() for block in blocks(page)]
PYTHON = [block for block in ALL_BLOCKS if block.language == "python"]
DIRECTIVES = {
    "literalinclude",
    "command-output",
    "toctree",
    "note",
    "eval-rst",
    "sila-labware-cli",
    "world-schema",
    "sila-feature",
    "sila-errors",
}
INSTALL_TOOLS = {"pip", "pytest", "cd", "python3.11", "lab-venv/bin/pip", "lab-venv/bin/sila-labware"}
RUN_VERBS = {"setup", "test", "docs", "demo", "serve", "bench", "world", "bluesky-demo"}
# Ray's own command line, installed with the project (pinned in pyproject.toml), for `bench --cluster`
RAY_VERBS = {"start", "stop", "status"}
DEFAULT_PORTS = (50052, 50053, 50054)  # what `serve` takes without --port-base: robot, station_a, station_b


def test_every_block_is_of_a_kind_that_is_checked() -> None:
    unchecked = [
        block.where()
        for block in ALL_BLOCKS
        if block.language not in {"python", "bash", "console", "yaml", "text"}
        and block.directive not in DIRECTIVES
    ]
    assert unchecked == [], f"code blocks nothing runs or checks: {unchecked}"


def shell_problem(line: str) -> str | None:
    """Why a shell line is not one the project provides or documents; None if it is."""
    line = line.strip().removeprefix("$ ")
    if not line or line.startswith("#"):
        return None
    words = shlex.split(line.split(" | ")[0], comments=True)
    if not words:
        return None
    program = words[0]
    if program in ("sila-labware", ".venv/bin/sila-labware") or program in INSTALL_TOOLS:
        return None
    if program in ("ray", ".venv/bin/ray"):
        return None if len(words) > 1 and words[1] in RAY_VERBS else f"ray has no verb we document: {line}"
    if program == "./run":
        return None if len(words) == 1 or words[1] in RUN_VERBS else f"./run has no verb {words[1]!r}"
    if program in ("python", ".venv/bin/python"):
        if words[1] == "-m":
            found = importlib.util.find_spec(words[2]) is not None
            return None if found else f"no module {words[2]}"
        return None if (REPOSITORY / words[1]).is_file() else f"no script {words[1]}"
    return f"{program!r} is not a command the project documents"


@pytest.mark.parametrize(
    "block", [b for b in ALL_BLOCKS if b.language in {"bash", "console"}], ids=Block.where
)
def test_shell_lines_are_commands_the_project_provides(block: Block) -> None:
    problems = [f"{line.strip()}: {why}" for line in block.text.splitlines() if (why := shell_problem(line))]
    assert problems == [], f"{block.where()}: {problems}"


@pytest.mark.parametrize("block", [b for b in ALL_BLOCKS if b.language == "yaml"], ids=Block.where)
def test_yaml_blocks_parse(block: Block) -> None:
    yaml.safe_load(block.text)


def test_the_github_actions_job_runs_the_downstream_tests_as_the_suite_does() -> None:
    job = yaml.safe_load((REPOSITORY / "examples/downstream/ci/github-actions.yml").read_text())
    steps = job["jobs"]["simulated-lab"]["steps"]
    commands = " ".join(step.get("run", "") for step in steps)
    assert "python -m pytest -n 2" in commands
    assert '"-n", "2"' in (REPOSITORY / "tests/examples/test_downstream.py").read_text()


@pytest.fixture(scope="module")
def lab(tmp_path_factory: pytest.TempPathFactory) -> Iterator[SimulatedLabSession]:
    with SimulatedLabSession(DEFAULT_WORLD, tmp_path_factory.mktemp("docs_lab")) as session:
        yield session


def test_the_python_blocks_are_the_ones_expected() -> None:
    # a new block runs below; this count only makes a block that went missing show
    assert len(PYTHON) >= 2


@pytest.mark.parametrize("block", PYTHON, ids=Block.where)
def test_python_block_runs_against_the_lab(
    block: Block, lab: SimulatedLabSession, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert lab.addresses is not None
    lab.reset()
    ports = [
        lab.addresses.robot[1],
        lab.addresses.stations["station_a"][1],
        lab.addresses.stations["station_b"][1],
    ]
    code = block.text
    for default, actual in zip(DEFAULT_PORTS, ports, strict=True):
        code = code.replace(str(default), str(actual))
    shutil.copy(lab.addresses.ca_file, tmp_path / "sila-labware-ca.pem")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, block.where(), "exec"), {"__name__": "docs_block"})  # noqa: S102
