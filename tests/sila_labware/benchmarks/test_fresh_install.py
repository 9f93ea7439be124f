"""The fresh-install benchmark runs each stage as from a new shell, not with this venv's ROS set-up."""

from __future__ import annotations

import os
import sys

from sila_labware.benchmarks.fresh_install import _timed, fresh_shell_environment


def test_a_stage_does_not_inherit_this_venvs_library_path_or_bootstrap_flag() -> None:
    assert "LD_LIBRARY_PATH" in os.environ  # the ROS wheels' start-up hook set it for this interpreter
    names = ("LD_LIBRARY_PATH", "_ROS_WHEELS_BOOTSTRAP_COMPLETE")
    probe = f"import os; print(*(os.environ.get(name, '-') for name in {names!r}))"
    # the base interpreter, outside this venv: no ROS start-up hook sets anything for it
    _, done = _timed([f"{sys.base_prefix}/bin/python3", "-c", probe])
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["-", "-"]


def test_everything_else_in_the_environment_is_kept() -> None:
    kept = fresh_shell_environment({"HOME": "/home/me", "PATH": "/usr/bin", "LD_LIBRARY_PATH": "/venv/lib"})
    assert kept == {"HOME": "/home/me", "PATH": "/usr/bin"}
