"""The documentation's pages and their fenced code blocks, for the tests of this folder."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[2]
DOCS = REPOSITORY / "docs"
README = REPOSITORY / "README.md"

_FENCE = re.compile(r"^(?P<fence>`{3,}|~{3,})(?P<info>[^\n`]*)$")


def pages() -> list[Path]:
    """README.md and every Markdown page of the site (generated output excluded)."""
    found = sorted(p for p in DOCS.rglob("*.md") if "_generated" not in p.parts and "_build" not in p.parts)
    return [README, *found]


def name(page: Path) -> str:
    return str(page.relative_to(REPOSITORY))


@dataclass(frozen=True)
class Block:
    page: Path
    line: int  # 1-based line of the opening fence
    info: str  # what follows the fence: a language, or `{directive} argument`
    text: str

    @property
    def language(self) -> str:
        return self.info.split()[0] if self.info.split() else ""

    @property
    def directive(self) -> str | None:
        match = re.match(r"\{([\w-]+)\}", self.info)
        return match.group(1) if match else None

    def where(self) -> str:
        return f"{name(self.page)}:{self.line}"


def blocks(page: Path) -> list[Block]:
    """The top-level fenced blocks of a page (a fence inside a fence is content)."""
    found: list[Block] = []
    lines = page.read_text().splitlines()
    index = 0
    while index < len(lines):
        match = _FENCE.match(lines[index].strip())
        if not match:
            index += 1
            continue
        fence, start = match.group("fence"), index
        index += 1
        body: list[str] = []
        while index < len(lines) and lines[index].strip() != fence:
            body.append(lines[index])
            index += 1
        found.append(Block(page, start + 1, match.group("info").strip(), "\n".join(body)))
        index += 1
    return found


def prose(page: Path) -> str:
    """The page without its fenced blocks (what a reader reads as text)."""
    lines = page.read_text().splitlines()
    for block in blocks(page):
        for number in range(block.line - 1, block.line + len(block.text.splitlines()) + 1):
            if number < len(lines):
                lines[number] = ""
    return "\n".join(lines)
