"""Every `sila-labware ...` line of the documentation parses with the command's own parser.

Lines are taken from the shell blocks (`sila-labware ...`, `$ sila-labware ...`, `./run <command>`,
`.venv/bin/sila-labware ...`) and from code spans in the text that are whole command lines (no
`[optional]` or `...` placeholders). Each is cut at a pipe, a redirection or a `;`, split as the
shell splits it, and given to `sila_labware.cli.build_parser().parse_args`; a usage error fails.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from sila_labware.cli import build_parser
from tests.docs.pages import blocks, name, pages, prose

SHELL = {"bash", "console", "shell", "sh"}
RUN_OWN = {"setup", "test", "docs"}  # ./run's own verbs; anything else goes to sila-labware
CODE_SPAN = re.compile(r"`(sila-labware [^`\n]+)`")


def words_of(line: str) -> list[str] | None:
    """The words of a `sila-labware` command on this line, without the program name; None if none."""
    line = line.strip().removeprefix("$ ")
    line = re.split(r"\s(?:\||;|&&|>|2>)\s", line)[0]
    try:
        words = shlex.split(line, comments=True)
    except ValueError:
        return None
    if not words:
        return None
    program = words[0]
    if program in ("sila-labware", ".venv/bin/sila-labware") or program.endswith("/bin/sila-labware"):
        return words[1:]
    if program == "./run" and len(words) > 1 and words[1] not in RUN_OWN:
        return words[1:]
    return None


def command_lines(page: Path) -> list[tuple[str, list[str]]]:
    found = []
    for block in blocks(page):
        if block.language in SHELL:
            for offset, line in enumerate(block.text.splitlines(), 1):
                words = words_of(line)
                if words is not None:
                    found.append((f"{name(page)}:{block.line + offset}: {line.strip()}", words))
    for span in CODE_SPAN.findall(prose(page)):
        if "[" not in span and "..." not in span:
            words = words_of(span)
            if words is not None:
                found.append((f"{name(page)}: `{span}`", words))
    return found


LINES = [line for page in pages() for line in command_lines(page)]


def test_the_documentation_has_command_lines_to_check() -> None:
    assert len(LINES) >= 10


@pytest.mark.parametrize(("where", "words"), LINES, ids=[where for where, _ in LINES])
def test_the_line_parses(where: str, words: list[str]) -> None:
    try:
        build_parser().parse_args(words)
    except SystemExit as exit_:
        pytest.fail(f"{where}: the parser refuses it (exit {exit_.code})")


def test_a_wrong_line_is_refused() -> None:
    with pytest.raises(SystemExit):
        build_parser().parse_args(words_of("sila-labware bench --no-such-option"))
    assert words_of("./run test tests/docs") is None
    assert words_of("$ sila-labware serve --print-config json | head -n 1 > lab.json") == [
        "serve",
        "--print-config",
        "json",
    ]
