"""The twin's start-up loads the robot's own interface packages only when asked for them.

Why: `./run` builds control_msgs, nav2_msgs and the rest into its venv, but a `pip install` of the
project builds only labware_interfaces (build_backend); the in-process twin must start without them.
"""

from __future__ import annotations

import subprocess
import sys

ROBOT_PACKAGES = ("control_msgs", "nav2_msgs", "play_motion2_msgs", "tf2_msgs")


def test_the_twins_start_up_imports_no_robot_interface_package() -> None:
    check = (
        "import sys, tiago_twin.startup; "
        f"loaded = [m for m in {ROBOT_PACKAGES!r} if m in sys.modules]; "
        "print(', '.join(loaded))"
    )
    done = subprocess.run([sys.executable, "-c", check], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == "", f"loaded at start-up: {done.stdout.strip()}"
