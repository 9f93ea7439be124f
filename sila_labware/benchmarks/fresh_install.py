"""From an empty venv to a delivered plate, as a new user gets there: venv, pip install, demo.

    python -m sila_labware.benchmarks.fresh_install [--source PATH_OR_URL] [--python python3.11]

Prints one JSON line: seconds for each stage (and how much of the install was the ROS 2 interface
build, from the build backend's own report), and the demo's verdict. Uses pip's cache like any
user's second install; pass --no-cache for a cold one. Needs the package registry.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[2]
BUILD_REPORT = re.compile(r"labware_interfaces built into the wheel in ([0-9.]+) s")


INHERITED_SETUP = (
    "LD_LIBRARY_PATH",
    "_ROS_WHEELS_BOOTSTRAP_COMPLETE",
    "VIRTUAL_ENV",
    "PYTHONPATH",
    "PYTHONHOME",
)
"""What a Python with the ROS wheels sets for itself and its children: the library path into its own
venv, and the flag that tells the ROS wheels' start-up hook it already ran. A new venv run with
them loads the running venv's ROS libraries (on Python 3.13 its demo then failed: "Could not
import 'rosidl_typesupport_c' for package 'rcl_interfaces'"), so every stage runs without them,
as from a user's fresh shell."""


def fresh_shell_environment(environment: dict[str, str]) -> dict[str, str]:
    """`environment` less what this interpreter's own set-up put there (INHERITED_SETUP)."""
    return {name: value for name, value in environment.items() if name not in INHERITED_SETUP}


def _timed(command: list[str], **options) -> tuple[float, subprocess.CompletedProcess]:
    started = time.monotonic()
    environment = fresh_shell_environment(dict(os.environ))
    done = subprocess.run(command, capture_output=True, text=True, check=False, env=environment, **options)
    return time.monotonic() - started, done


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m sila_labware.benchmarks.fresh_install")
    parser.add_argument("--source", default=str(REPOSITORY), help="what to pip install (default: this clone)")
    parser.add_argument("--python", default=sys.executable, help="interpreter for the new venv")
    parser.add_argument("--port-base", type=int, default=58200)
    parser.add_argument("--no-cache", action="store_true", help="pip without its download cache")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="fresh_install_") as scratch:
        venv = Path(scratch) / "venv"
        venv_s, done = _timed([args.python, "-m", "venv", str(venv)])
        if done.returncode != 0:
            sys.stderr.write(done.stderr)
            return 1
        pip = [str(venv / "bin" / "python"), "-m", "pip", "install", "-v", "--disable-pip-version-check"]
        install_s, done = _timed([*pip, *(["--no-cache-dir"] if args.no_cache else []), args.source])
        if done.returncode != 0:
            sys.stderr.write(done.stdout[-4000:] + done.stderr[-4000:])
            return 1
        build = BUILD_REPORT.search(done.stdout + done.stderr)
        demo_s, demo = _timed(
            [str(venv / "bin" / "sila-labware"), "demo", "--json", "--port-base", str(args.port_base)],
            cwd=scratch,
            timeout=600,
        )
        verdict = json.loads(demo.stdout.strip().splitlines()[-1]) if demo.stdout.strip() else {}
        figures = {
            "python": subprocess.run([args.python, "-V"], capture_output=True, text=True).stdout.strip(),
            "venv_s": round(venv_s, 1),
            "pip_install_s": round(install_s, 1),
            "interface_build_s": float(build.group(1)) if build else None,
            "demo_s": round(demo_s, 1),
            "demo_success": bool(verdict.get("success")),
            "total_s": round(venv_s + install_s + demo_s, 1),
        }
        if not figures["demo_success"]:  # the venv goes with the scratch folder: keep what the demo said
            figures["demo_error"] = verdict.get("error") or demo.stderr.strip()[-2000:]
        print(json.dumps(figures))
        return 0 if figures["demo_success"] else 1


if __name__ == "__main__":
    sys.exit(main())
