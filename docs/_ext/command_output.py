"""Run commands at build time and show what they print or draw.

- `{command-output}` runs the command given as its argument (from the repository root, through the
  venv's `sila-labware` or `python`) and shows the command and its output as a console block. A
  command that exits other than the `:returncode:` option says (default 0) fails the build, so a
  shown output is one the code produces today.
- At `builder-inited`, `world check --png` draws the floor plans the pages show into
  `docs/_generated/` (ignored by git): pictures the code can draw are not committed.
"""

from __future__ import annotations

import shlex
import subprocess
import sys
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import directives
from sphinx.application import Sphinx
from sphinx.errors import ExtensionError
from sphinx.util.docutils import SphinxDirective

REPOSITORY = Path(__file__).resolve().parents[2]
GENERATED = REPOSITORY / "docs" / "_generated"
# world file -> picture, drawn by `sila-labware world check FILE --png PICTURE`
PICTURES = {
    "lab_description/worlds/default.yaml": "world_default.png",
    "lab_description/worlds/furnished_lab.yaml": "world_furnished_lab.png",
    "lab_description/worlds/bench_in_the_way.yaml": "world_bench_in_the_way.png",
}


def _argv(command: str) -> list[str]:
    words = shlex.split(command)
    bin_dir = Path(sys.executable).parent
    if words[0] == "sila-labware":
        return [str(bin_dir / "sila-labware"), *words[1:]]
    if words[0] == "python":
        return [sys.executable, *words[1:]]
    raise ExtensionError(f"command-output runs sila-labware or python only, not {words[0]!r}")


def _run(command: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        _argv(command), cwd=REPOSITORY, capture_output=True, text=True, timeout=120, check=False
    )


class CommandOutput(SphinxDirective):
    required_arguments = 1
    final_argument_whitespace = True
    option_spec = {"returncode": directives.nonnegative_int}

    def run(self) -> list[nodes.Node]:
        command = self.arguments[0]
        want = self.options.get("returncode", 0)
        done = _run(command)
        if done.returncode != want:
            raise self.error(
                f"`{command}` exited {done.returncode}, the page says {want}:\n{done.stdout}{done.stderr}"
            )
        text = f"$ {command}\n{done.stdout.rstrip()}"
        if want:
            text += f"\n$ echo $?\n{want}"
        return [nodes.literal_block(text, text, language="console")]


def draw_pictures(app: Sphinx) -> None:
    GENERATED.mkdir(exist_ok=True)
    # side by side: each is a few seconds of planning and drawing
    running = {
        world: subprocess.Popen(
            _argv(f"sila-labware world check {world} --png {GENERATED / picture}"),
            cwd=REPOSITORY,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        for world, picture in PICTURES.items()
    }
    for world, process in running.items():
        output, _ = process.communicate(timeout=120)
        if process.returncode != 0:
            raise ExtensionError(f"world check {world} failed:\n{output}")


def setup(app: Sphinx) -> dict[str, object]:
    app.add_directive("command-output", CommandOutput)
    app.connect("builder-inited", draw_pictures)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
