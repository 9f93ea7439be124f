"""examples/downstream is a project of its own (its pyproject, its tests) that uses this one only
through its pytest plugin. It runs here as its users run it: pytest in that folder, two xdist
workers, each with its own simulated lab (own ROS domain, own ports), reset before every test."""

from __future__ import annotations

import os
import re
import subprocess
import sys

from tests.helpers.sila_stack import REPOSITORY

DOWNSTREAM = REPOSITORY / "examples" / "downstream"


def test_the_downstream_project_runs_its_workflows_on_two_labs_side_by_side() -> None:
    environment = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_DOMAIN_ID", "PYTEST_"))}
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-n", "2"],
        cwd=DOWNSTREAM,
        env=environment,
        capture_output=True,
        text=True,
        timeout=240,
    )
    summary = done.stdout[-3000:] + done.stderr[-2000:]
    assert done.returncode == 0, summary
    assert re.search(r"\b10 passed\b", done.stdout), summary
