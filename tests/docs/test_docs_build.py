"""The documentation site builds, with every warning an error (as `./run docs` builds it)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from tests.docs.pages import DOCS


def test_the_site_builds_with_warnings_as_errors(tmp_path: Path) -> None:
    sphinx_build = Path(sys.executable).parent / "sphinx-build"
    done = subprocess.run(
        [
            str(sphinx_build),
            "-W",
            "--keep-going",
            "-q",
            "-b",
            "html",
            "-d",
            str(tmp_path / "doctrees"),
            str(DOCS),
            str(tmp_path / "html"),
        ],
        capture_output=True,
        text=True,
        timeout=240,
        check=False,
    )
    assert done.returncode == 0, f"sphinx-build failed:\n{done.stdout}\n{done.stderr}"
    assert (tmp_path / "html" / "index.html").is_file()
    assert (tmp_path / "html" / "reference" / "cli.html").is_file()
