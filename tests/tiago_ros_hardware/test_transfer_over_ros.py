"""One whole transfer with the skills on the robot's own ROS 2 interfaces: `sila-labware demo
--ros-adapter`, as a user runs it.

The SiLA client, the bridge and the task level are the usual ones; the skills reach the simulated
TIAGo++ only through tiago_ros_hardware over DDS (its controllers' FollowJointTrajectory actions,
/joint_states, odometry, the head camera's topics, the velocity command, Nav2's navigation and
docking), as they would a real robot. Success is the demo's: the plate rests in the destination
nest, read from physics. The twin runs at most 5 times real time, and slower on a busy machine.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

from tests.helpers.sila_stack import free_port_base

CLI = str(Path(sys.executable).with_name("sila-labware"))
CONTROLLER_GOALS = re.compile(r"the robot's own interfaces: controller goals: (.*)")


def test_a_transfer_over_the_robots_own_interfaces_delivers(tmp_path: Path) -> None:
    log_dir = tmp_path / "logs"
    arguments = ["demo", "--ros-adapter", "--json", "--insecure", "--no-discovery", "--log-dir", str(log_dir)]
    done = subprocess.run(
        [CLI, *arguments, "--port-base", str(free_port_base(4))], capture_output=True, text=True, timeout=600
    )
    report = json.loads(done.stdout)
    assert report["success"] is True, (report, done.stderr[-3000:])
    assert done.returncode == 0
    robot_log = (log_dir / "sim_node.log").read_text()
    assert "the skills reach the robot through its own ROS 2 interfaces" in robot_log
    counts = dict(
        (group, int(count))
        for group, count in (item.split() for item in CONTROLLER_GOALS.search(robot_log)[1].split(", "))
    )
    # every arm motion, the torso, the head's looks and the gripper went through the controllers' actions
    assert (
        counts.get("arm_right", 0) > 10 and counts.get("head", 0) > 0 and counts.get("gripper_right", 0) >= 4
    )
