"""Commit ids and campaign seeds appear only on the benchmarks pages (the figures and their history).

Elsewhere the documentation says what holds and why; which trial revealed a rule, and at which
commit, is history. A commit id here is 7 to 40 hex digits with at least one digit and one of a-f
(so neither a plain number nor a word), except an upstream source cited as `owner/repository@commit`;
a campaign seed is a number of three or more digits after
"seed", "trial", "--replay" or "--save-layout", or any bare number of five or six digits other than
the ports the pages use as examples.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.docs.pages import DOCS, name, pages

COMMIT = re.compile(r"(?<![\w/#.@-])(?=[0-9a-f]*[0-9])(?=[0-9a-f]*[a-f])[0-9a-f]{7,40}(?![\w/-])")
SEED_AFTER_WORD = re.compile(r"(?i)\b(?:seeds?|trials?|--replay|--save-layout|layouts?)\s+(\d{3,})\b")
BARE_NUMBER = re.compile(r"(?<![\w.,:/-])(\d{5,6})(?!\w|[.,]\d)")
EXAMPLE_PORTS = {"50052", "50053", "50054", "57000"}


def off_the_benchmarks_pages() -> list[Path]:
    return [page for page in pages() if not page.is_relative_to(DOCS / "benchmarks")]


def history_in(text: str) -> list[str]:
    found = [f"commit id {m.group(0)}" for m in COMMIT.finditer(text)]
    found += [f"seed {m.group(1)} ({m.group(0)!r})" for m in SEED_AFTER_WORD.finditer(text)]
    found += [f"number {m.group(1)}" for m in BARE_NUMBER.finditer(text) if m.group(1) not in EXAMPLE_PORTS]
    return found


@pytest.mark.parametrize("page", off_the_benchmarks_pages(), ids=name)
def test_no_commit_ids_or_seeds_outside_the_benchmarks_pages(page: Path) -> None:
    lines = [
        f"{name(page)}:{number}: {what}"
        for number, line in enumerate(page.read_text().splitlines(), 1)
        for what in history_in(line)
    ]
    assert not lines, "history belongs on docs/benchmarks/:\n" + "\n".join(lines)


def test_the_rule_finds_what_it_is_meant_to_find() -> None:
    assert history_in("at `a1b2b8b`, 200/200") == ["commit id a1b2b8b"]
    assert history_in("random layout 91028 put a pad") and history_in("seed 2041 stopped")
    assert history_in("`bench --replay 10145`")
    assert not history_in("`ros2/geometry2@f3b6a866d8d2d3b48dd735144849842e4ae81b7d`")
    assert not history_in("port 50052, 127.0.0.1, 0.265 m, 1,071 results, decade, 2 cores, seed 1")
    assert not history_in("server_uuid 6c1e, colour #4a9b3cd, sub-position 12")
