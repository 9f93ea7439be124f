"""The robot's limits come from one configuration, and no step of a transfer beats its minimum under them.

Why: a lab runs its robot with the limits its navigation and controllers are set to; the simulator
must then move no faster than those, and the time budget must judge each step against the same
limits. A real transfer (robot side, sequencer, physics) runs under the shipped limits and under a
lab's slower file; every step's robot time is at least its minimum, and the minima follow the file.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from robot_port.trajectory_timing import RAMP_S
from sila_labware.deployment import robot_limits_file
from tiago_description import robot_limits
from tiago_description.robot_limits import DEFAULT_LIMITS_FILE, RobotLimitsError, load_limits

SLOW_LIMITS = """\
base:
  max_velocity: [0.5, 0.0, 0.6]
  max_accel: [0.3, 0.0, 0.8]
joint_limits:
  torso_lift_joint: {max_velocity: 0.05}
  arm_{side}_6_joint: {max_velocity: 1.0}
  gripper_{side}_left_finger_joint: {max_velocity: 0.04}
  gripper_{side}_right_finger_joint: {max_velocity: 0.04}
"""
STEP_TOLERANCE_S = 0.02  # a goal's span is read at the simulation's step, 1/60 s
ROW = re.compile(r"^\| (\S+) \| ([\d.]+) \| ([\d.]+) \| (-?[\d.]+) \| [\d.]+ \| (.*) \|$")


def _transfer_budget(tmp_path: Path, limits_file: Path) -> tuple[str, list[tuple[str, float, float, str]]]:
    """One benchmark transfer under `limits_file`: its output and (step, took s, minimum s, what moved)
    per goal."""
    environment = {**os.environ, robot_limits.ENVIRONMENT_VARIABLE: str(limits_file)}
    done = subprocess.run(
        [sys.executable, "-m", "tiago_sim.measuring.benchmark", "--seed", "3", "--budget"],
        env=environment,
        capture_output=True,
        text=True,
        timeout=240,
        check=False,
    )
    logs = re.search(r"logs in (\S+)\):", done.stdout)
    if logs:
        shutil.rmtree(logs[1], ignore_errors=True)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    rows = [
        (m[1], float(m[2]), float(m[3]), m[5]) for line in done.stdout.splitlines() if (m := ROW.match(line))
    ]
    return done.stdout, rows


@pytest.mark.parametrize("slow", [False, True], ids=["shipped limits", "a lab's slower limits"])
def test_no_step_of_a_transfer_is_faster_than_its_minimum_under_the_limits_it_ran_with(
    tmp_path: Path, slow: bool
) -> None:
    limits_file = DEFAULT_LIMITS_FILE
    if slow:
        limits_file = tmp_path / "slow.yaml"
        limits_file.write_text(SLOW_LIMITS)
    output, rows = _transfer_budget(tmp_path, limits_file)
    assert "placement: in_nest=True" in output
    assert len(rows) > 20
    faster = [(step, took, least) for step, took, least, _moved in rows if took < least - STEP_TOLERANCE_S]
    assert not faster, faster
    # the minima follow the file: the torso's 0.17 m rise to the bench height at the first station
    # (beside the final approach, or beside the drive when drive_posture raises it there)
    rises = [
        found
        for step, _took, _least, moved in rows
        if step.startswith("GetLabware:")
        and (found := re.search(r"torso_lift_joint 0\.17 m of \d+ joints \(([\d.]+) s\)", moved))
    ]
    assert rises, rows
    rise = rises[0]
    torso_speed = 0.05 if slow else 0.07
    assert float(rise[1]) == pytest.approx(0.17 / torso_speed + RAMP_S, abs=0.05)


def test_the_shipped_file_is_the_hardware_and_a_file_beyond_it_is_refused_by_name(tmp_path: Path) -> None:
    shipped = load_limits()
    assert dict(shipped.joint_velocity) == robot_limits.hardware_velocity_limits()
    assert (shipped.linear_speed, shipped.linear_accel) == (1.0, 0.5)
    beyond = tmp_path / "beyond.yaml"
    beyond.write_text("joint_limits:\n  arm_{side}_6_joint: {max_velocity: 2.0}\n")
    with pytest.raises(RobotLimitsError, match=r"arm_\{side\}_6_joint: 2.0 is outside 0 .. 1.76"):
        load_limits(beyond)
    unknown = tmp_path / "unknown.yaml"
    unknown.write_text("joint_limits:\n  elbow_joint: {max_velocity: 1.0}\n")
    with pytest.raises(RobotLimitsError, match="the robot has no joint elbow_joint"):
        load_limits(unknown)
    partial = tmp_path / "partial.yaml"
    partial.write_text("base:\n  max_velocity: [0.4, 0, 0.5]\n  max_accel: [0.2, 0, 0.5]\n")
    left_out = load_limits(partial)
    assert left_out.linear_speed == 0.4
    assert left_out.joint_velocity == shipped.joint_velocity  # a joint left out keeps its hardware limit


def test_the_cli_refuses_a_limits_file_before_anything_starts_and_names_the_field(tmp_path: Path) -> None:
    beyond = tmp_path / "fast.yaml"
    beyond.write_text("base:\n  max_velocity: [1.5, 0, 1.0]\n  max_accel: [0.5, 0, 1.0]\n")
    assert robot_limits_file.ENVIRONMENT_VARIABLE == robot_limits.ENVIRONMENT_VARIABLE
    done = subprocess.run(
        [sys.executable, "-m", "sila_labware", "demo", "--robot-limits", str(beyond)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 2
    assert "--robot-limits" in done.stderr
    assert "base.max_velocity[0] (linear speed): 1.5 is outside" in done.stderr
