"""`./run` as a user types it, without letting a test trigger a reinstall.

Why: `./run VERB` sets up first when pyproject.toml, `run` or the interfaces changed since the last
set-up; inside a test that would mean minutes of pip and cmake (and a second install racing the
first under -n 2). `./run test` sets up before the tests start, so there the set-up is current;
a test run with a stale set-up fails here, saying so, instead of reinstalling.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[2]
RUN = str(REPOSITORY / "run")


def assert_set_up() -> None:
    """`./run setup --check`: the set-up is current, so `./run VERB` installs nothing."""
    done = subprocess.run([RUN, "setup", "--check"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, f"the set-up is stale, run `./run setup` first: {done.stderr.strip()}"
