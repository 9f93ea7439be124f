"""The seam between the robot's skills and the simulator, checked: the hardware port and nothing else.

Why: the promise that the software running the twin runs the robot holds only while the skills see
the robot through `robot_port.RobotHardware` alone. An attribute read on a hardware object that the
protocol lacks would work against the simulator and fail on a robot; a package that imports both
sides would let the skills reach past the port. The import layers are in test_architecture.py;
these tests add what a layer table cannot see.
"""

from __future__ import annotations

import ast
import inspect
import subprocess
import sys
from pathlib import Path

from robot_port.execution import Execution
from robot_port.hardware import RobotHardware
from tiago_sim.sim_node.hardware import MotionExecution, SimulatedHardware
from tiago_sim.sim_node.navigation import NavigationGoal

REPOSITORY = Path(__file__).resolve().parents[1]
PORT_METHODS = {
    name for name, member in vars(RobotHardware).items() if callable(member) and not name.startswith("_")
}
EXECUTION_MEMBERS = {
    name for name in [*vars(Execution), *Execution.__annotations__] if not name.startswith("_")
}
# Names under which the skills hold a hardware object (GoalRun.read's lambdas, attributes).
HARDWARE_NAMES = {"hardware"}
SIMULATOR_WORDS = {"sim", "sim_thread", "Simulation", "SimThread", "pybullet"}


def _skills_sources() -> list[tuple[Path, ast.AST]]:
    return [
        (path, ast.parse(path.read_text(), str(path)))
        for path in sorted((REPOSITORY / "tiago_skills").rglob("*.py"))
    ]


def _imported_tops(tree: ast.AST) -> set[str]:
    tops = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            tops |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            tops.add(node.module.split(".")[0])
    return tops


def test_the_port_offers_what_its_issue_names() -> None:
    assert PORT_METHODS == {
        "now",
        "joint_positions",
        "odometry",
        "pose_estimate",
        "is_docked",
        "laser_scan",
        "capture_head_camera",
        "follow_joint_trajectory",
        "gripper",
        "command_velocity",
        "drive_to",
        "navigate_to",
        "plan_path",
        "dock",
        "undock",
    }


def test_the_skills_ask_the_hardware_for_nothing_beyond_the_port() -> None:
    """Every `hardware.<name>` and `<...>.hardware.<name>` in the skills names a port method."""
    beyond = []
    for path, tree in _skills_sources():
        for node in ast.walk(tree):
            if not isinstance(node, ast.Attribute):
                continue
            holder = node.value
            held_by = holder.id if isinstance(holder, ast.Name) else getattr(holder, "attr", None)
            if held_by in HARDWARE_NAMES and node.attr not in PORT_METHODS:
                beyond.append(f"{path.relative_to(REPOSITORY)}:{node.lineno} hardware.{node.attr}")
    assert beyond == [], "calls past the hardware port:\n" + "\n".join(beyond)


def test_the_skills_never_name_the_simulator() -> None:
    """No name, attribute or argument of the skills refers to the simulation (a `sim` lambda
    argument would mean a job handed to the sim thread)."""
    named = []
    for path, tree in _skills_sources():
        for node in ast.walk(tree):
            name = (
                node.id
                if isinstance(node, ast.Name)
                else node.attr
                if isinstance(node, ast.Attribute)
                else node.arg
                if isinstance(node, ast.arg)
                else None
            )
            if name in SIMULATOR_WORDS:
                named.append(f"{path.relative_to(REPOSITORY)}:{node.lineno} {name}")
    assert named == [], "\n".join(named)


def test_only_the_start_up_imports_both_the_skills_and_the_simulator() -> None:
    both = []
    for top in ("tiago_sim", "tiago_skills", "tiago_twin", "sila_labware", "ros_bridge"):
        for path in sorted((REPOSITORY / top).rglob("*.py")):
            tops = _imported_tops(ast.parse(path.read_text(), str(path))) | {top}
            if {"tiago_sim", "tiago_skills"} <= tops and top != "tiago_twin":
                both.append(str(path.relative_to(REPOSITORY)))
    assert both == []


def test_importing_the_skills_loads_neither_pybullet_nor_the_simulator() -> None:
    """Checked in a fresh interpreter: what the skills pull in, however indirectly."""
    modules = [f"tiago_skills.{path.stem}" for path in sorted((REPOSITORY / "tiago_skills").glob("*.py"))] + [
        f"tiago_skills.perception.{path.stem}"
        for path in (REPOSITORY / "tiago_skills/perception").glob("*.py")
    ]
    probe = (
        f"import importlib, sys\nfor m in {modules!r}: importlib.import_module(m)\n"
        "print(sorted(m for m in sys.modules if m == 'pybullet' or m.startswith('tiago_sim')))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", probe], cwd=REPOSITORY, capture_output=True, text=True, check=True
    ).stdout.strip()
    assert loaded == "[]"


def test_the_simulator_implements_every_port_method_with_its_parameters() -> None:
    for name in sorted(PORT_METHODS):
        port = inspect.signature(getattr(RobotHardware, name))
        simulated = inspect.signature(getattr(SimulatedHardware, name))
        assert list(simulated.parameters) == list(port.parameters), name


def test_the_simulator_s_executions_have_every_member_of_the_port_s() -> None:
    assert EXECUTION_MEMBERS == {
        "name", "done", "success", "error_code", "message", "progress", "phase", "remaining_s",
        "result", "wait", "cancel",
    }  # fmt: skip
    assert EXECUTION_MEMBERS - {"name"} <= set(dir(MotionExecution))  # `name`: set from the motion's
    assert isinstance(NavigationGoal("probe"), Execution)
