"""Every command as a user types it: the installed `sila-labware` console script and `./run`, to
their first useful output (or their whole run, where that is cheap).

Where the others are: `serve` and `demo` (through the console script, and `./run demo` under
Ctrl-C) in test_cli.py; `demo --json`, `bench --json` and `serve --print-config json` refusals and
`bench --save-layout` in test_json_outcome.py; `serve` with the queue server in
tests/ros_bridge/test_bluesky_queueserver.py. `./run test` is the suite itself.
"""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

from tests.helpers.run_script import REPOSITORY, RUN, assert_set_up

SILA_LABWARE = str(Path(sys.executable).with_name("sila-labware"))
WORLD = "lab_description/worlds/default.yaml"
WORLD_SUMMARY = "default lab: lab_description/worlds/default.yaml"


def test_world_check_summarises_the_shipped_world() -> None:
    done = subprocess.run(
        [SILA_LABWARE, "world", "check", WORLD], capture_output=True, text=True, timeout=120, cwd=REPOSITORY
    )
    assert (done.returncode, done.stderr) == (0, ""), done.stderr
    assert done.stdout.startswith(WORLD_SUMMARY), done.stdout
    assert "every POI reachable from every other" in done.stdout


def test_bluesky_demo_runs_the_plan_and_brings_the_plate_back(tmp_path: Path) -> None:
    """The whole command (about 30 s): the robot side, the plan on a RunEngine, the physics check.
    (It once crashed before starting: its options had no --name, which the shared checks read.)"""
    done = subprocess.run(
        [SILA_LABWARE, "bluesky-demo", "--log-dir", str(tmp_path / "logs")],
        capture_output=True,
        text=True,
        timeout=600,
        stdin=subprocess.DEVNULL,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert "running the Bluesky plan" in done.stderr
    assert done.stderr.rstrip().endswith("bluesky demo: the plate is back in its starting nest"), done.stderr[
        -2000:
    ]
    assert "Traceback" not in done.stderr


def test_run_setup_check_and_setup_install_nothing_when_current() -> None:
    assert_set_up()
    started = time.monotonic()
    done = subprocess.run([RUN, "setup"], capture_output=True, text=True, timeout=120)
    assert (done.returncode, done.stdout, done.stderr) == (0, "", ""), done.stderr
    assert time.monotonic() - started < 30.0, "a current set-up is only a check of the stamps"


def test_run_passes_other_verbs_to_sila_labware() -> None:
    assert_set_up()
    done = subprocess.run(
        [RUN, "world", "check", WORLD], capture_output=True, text=True, timeout=120, cwd=REPOSITORY
    )
    assert (done.returncode, done.stderr) == (0, ""), done.stderr
    assert done.stdout.startswith(WORLD_SUMMARY), done.stdout


def test_run_docs_reaches_sphinx_build() -> None:
    """Wiring only: the site's build itself is tests/docs/test_docs_build.py."""
    assert_set_up()
    done = subprocess.run([RUN, "docs", "--version"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("sphinx-build "), done.stdout
