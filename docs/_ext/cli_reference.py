"""`{sila-labware-cli}`: the command-line reference, generated from the parser the command uses.

Reads `sila_labware.cli.build_parser()` at build time and writes one section per subcommand (and
per sub-subcommand, such as `world check`): its usage line, its help and every option with its help
text. Nothing is copied by hand, so the page cannot drift from the command.
"""

from __future__ import annotations

import argparse

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective
from tables import table


def _subcommands(parser: argparse.ArgumentParser) -> list[tuple[str, argparse.ArgumentParser, str]]:
    found = []
    for action in parser._actions:  # argparse keeps its subcommands only here
        if isinstance(action, argparse._SubParsersAction):
            helps = {choice.dest: choice.help or "" for choice in action._choices_actions}
            for name, sub in action.choices.items():
                found.append((name, sub, helps.get(name, "")))
    return found


def _option_rows(parser: argparse.ArgumentParser) -> list[tuple[str, str]]:
    rows = []
    for action in parser._actions:
        if isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)):
            continue
        if action.option_strings:
            name = ", ".join(action.option_strings)
            if action.nargs != 0:
                name += " " + (action.metavar if isinstance(action.metavar, str) else action.dest.upper())
        else:
            name = action.metavar if isinstance(action.metavar, str) else action.dest
        text = (action.help or "") % {"default": action.default, "prog": parser.prog}
        if action.choices and not isinstance(action.choices, dict):
            text += f" (one of: {', '.join(str(c) for c in action.choices)})"
        rows.append((name, text))
    return rows


class CliReference(SphinxDirective):
    has_content = False

    def _section(self, title: str, parser: argparse.ArgumentParser, help_text: str) -> nodes.container:
        # a rubric, not a section: sections returned by a directive confuse the document's outline
        section = nodes.container(ids=[nodes.make_id("cli " + title)])
        section += nodes.rubric(text=title)
        if help_text or parser.description:
            section += nodes.paragraph(text=help_text or parser.description)
        usage = parser.format_usage().removeprefix("usage: ").strip()
        section += nodes.literal_block(usage, usage, language="text")
        rows = _option_rows(parser)
        if rows:
            section += table(("option", "what it does"), (35, 65), rows)
        for name, sub, sub_help in _subcommands(parser):
            section += self._section(f"{title} {name}", sub, sub_help)
        return section

    def run(self) -> list[nodes.Node]:
        from sila_labware.cli import build_parser

        parser = build_parser()
        self.env.note_dependency(str(self.env.srcdir.parent / "sila_labware" / "cli.py"))
        return [self._section(f"sila-labware {name}", sub, text) for name, sub, text in _subcommands(parser)]


def setup(app: Sphinx) -> dict[str, object]:
    app.add_directive("sila-labware-cli", CliReference)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
