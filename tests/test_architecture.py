"""The layers of the tree, checked: which package may import which, and how long a module may grow.

Why a test: the README's layout table promises that imports run one way (client -> SiLA servers
-> bridge -> ROS interfaces <- robot side), that the task level a real TIAGo++ keeps (the
sequencer) imports nothing of the simulation, and that the robot's skills and the simulator meet
only at the hardware port (robot_port), wired together by the start-up (tiago_twin) alone. A
promise nobody checks erodes one convenient import at a time. Every import statement counts,
including those inside functions.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[1]
TOP_PACKAGES = (
    "labware_model",
    "robot_port",
    "tiago_description",
    "lab_description",
    "tiago_skills",
    "tiago_sim",
    "tiago_twin",
    "tiago_ros_hardware",
    "ros_bridge",
    "sila_labware",
)
MAX_MODULE_LINES = 400
# The robot as described and the lab as described: what both the skills and the simulator read.
DESCRIPTIONS = {"tiago_description", "lab_description"}

# Each unit (a subpackage, or a module at a package's root) and the units of ours it may import.
# A unit may always import itself. Lower layers come first.
ALLOWED: dict[str, set[str]] = {
    "labware_model": set(),
    # the hardware port: types and a protocol, the seam between the skills and any robot
    "robot_port": set(),
    # an rclpy action client safe from any thread: for every ROS client on the robot's side
    "robot_port.action_client": set(),
    "tiago_description": set(),
    "lab_description": {"labware_model", "tiago_description"},
    # the robot's software: sees the robot only through the port, never the simulator
    "tiago_skills.perception": {"robot_port", "tiago_description"},
    "tiago_skills": {"labware_model", "robot_port", *DESCRIPTIONS, "tiago_skills.perception"},
    # the starter's pid, read first by a robot-side process (node_main stops when it is gone)
    "tiago_sim.started_by": set(),
    "tiago_sim.node_main": {"tiago_sim.started_by"},
    "tiago_sim.navigation": {"labware_model", *DESCRIPTIONS},
    # `world check`: the loader's rules, the planner's paths between POIs, the picture
    "tiago_sim.inspection": {"labware_model", *DESCRIPTIONS, "tiago_sim.navigation"},
    # random labs and obstacles for campaigns: world files checked as the loader and `world check` do
    "tiago_sim.layouts": {*DESCRIPTIONS, "tiago_sim.navigation", "tiago_sim.inspection"},
    "tiago_sim.physics": {"labware_model", "robot_port", *DESCRIPTIONS, "tiago_sim.navigation"},
    "tiago_sim.measuring": {
        "labware_model",
        "robot_port",
        *DESCRIPTIONS,
        "tiago_sim.physics",
        "tiago_sim.navigation",
    },
    # the simulator's ROS side: the hardware port on the simulation, sensors, the navigation stand-in
    "tiago_sim.sim_node": {
        "labware_model",
        "robot_port",
        "robot_port.action_client",
        *DESCRIPTIONS,
        "tiago_sim.node_main",
        "tiago_sim.physics",
        "tiago_sim.measuring",
        "tiago_sim.navigation",
    },
    # the task level: a ROS client of the robot's actions, as on the real robot
    "tiago_sim.sequencer": {
        "labware_model",
        "robot_port.action_client",
        "tiago_sim.node_main",
        "tiago_sim.started_by",
        "lab_description",
    },
    # the hardware port over a TIAGo++'s own ROS 2 interfaces (a real robot, or the simulator's)
    "tiago_ros_hardware": {"robot_port", "robot_port.action_client", "tiago_description"},
    # the start-up: the one unit that imports both the simulator and the skills
    "tiago_twin": {
        "robot_port",
        "tiago_ros_hardware",
        *DESCRIPTIONS,
        "tiago_skills",
        "tiago_skills.perception",
        "tiago_sim.node_main",
        "tiago_sim.started_by",
        "tiago_sim.sim_node",
        "tiago_sim.physics",
        "tiago_sim.measuring",
    },
    "ros_bridge": {"labware_model"},
    "ros_bridge.bluesky": {"labware_model", "ros_bridge"},
    "sila_labware.device": {"labware_model", "ros_bridge"},
    "sila_labware.client": {"labware_model"},
    "sila_labware.servers": {"labware_model", "ros_bridge", "sila_labware.device"},
    "sila_labware.deployment": {
        "labware_model",
        "ros_bridge",
        "ros_bridge.bluesky",
        "sila_labware.device",
        "sila_labware.client",
        "sila_labware.servers",
    },
    "sila_labware.benchmarks": {
        "labware_model",
        "ros_bridge",
        "sila_labware.device",
        "sila_labware.client",
        "sila_labware.servers",
        "sila_labware.deployment",
    },
    # the simulated lab for downstream projects' tests (pytest plugin)
    "sila_labware.testing": {
        "ros_bridge",
        "sila_labware.client",
        "sila_labware.servers",
        "sila_labware.deployment",
    },
    "sila_labware.cli": {
        "ros_bridge",
        "ros_bridge.bluesky",
        "sila_labware.servers",
        "sila_labware.deployment",
        "sila_labware.benchmarks",
    },
    "sila_labware.__main__": {"sila_labware.cli"},
}
# The packages themselves (their __init__ modules): documentation, no imports of ours.
PACKAGE_ROOTS = {top: set() for top in TOP_PACKAGES if top not in ALLOWED}

# Outside libraries a unit must never import directly (what the house style promises).
FORBIDDEN_LIBRARIES: dict[str, set[str]] = {
    **{unit: {"sila2"} for unit in ALLOWED if unit.startswith("tiago_sim.")},  # first: the rows below win
    "robot_port": {"rclpy", "sila2", "pybullet", "cv2", "pinocchio", "yaml"},
    "robot_port.action_client": {"sila2", "pybullet", "cv2", "pinocchio", "yaml"},
    "tiago_description": {"rclpy", "sila2", "pybullet", "cv2"},
    "lab_description": {"rclpy", "sila2", "pybullet", "cv2"},
    "tiago_skills": {"pybullet", "sila2"},
    "tiago_skills.perception": {"pybullet", "rclpy", "sila2"},
    "labware_model": {"numpy", "rclpy", "sila2", "pybullet", "cv2", "yaml"},
    "ros_bridge": {"sila2", "pybullet", "cv2"},
    "ros_bridge.bluesky": {"sila2", "pybullet", "cv2"},
    "sila_labware.device": {"sila2", "rclpy", "pybullet", "cv2"},
    "sila_labware.client": {"rclpy", "pybullet", "cv2"},
    "sila_labware.servers": {"pybullet", "cv2"},
    "sila_labware.deployment": {"pybullet", "cv2"},
    "tiago_sim.sequencer": {"pybullet", "cv2", "pinocchio", "sila2"},
    # maps, planning and localisation: plain geometry a real robot's stack would run too
    "tiago_sim.navigation": {"pybullet", "rclpy", "sila2"},
}


def _modules() -> Iterator[tuple[str, Path]]:
    for top in TOP_PACKAGES:
        for path in sorted((REPOSITORY / top).rglob("*.py")):
            relative = path.relative_to(REPOSITORY)
            if "generated" in relative.parts:
                continue
            yield ".".join(relative.with_suffix("").parts).removesuffix(".__init__"), path


def _unit_of(module: str) -> str:
    """The layer a module belongs to: its subpackage, or itself at a package's root."""
    if module in PACKAGE_ROOTS:
        return module
    for unit in sorted(ALLOWED, key=len, reverse=True):
        if module == unit or module.startswith(unit + "."):
            return unit
    return module


def _imports(module: str, path: Path) -> Iterator[str]:
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            yield base
            yield from (f"{base}.{alias.name}" for alias in node.names)


def test_every_unit_of_the_tree_has_a_place_in_the_layers() -> None:
    placed = ALLOWED.keys() | PACKAGE_ROOTS.keys()
    unplaced = sorted({module for module, _ in _modules() if _unit_of(module) not in placed})
    assert unplaced == [], "modules outside every layer (add them to ALLOWED): " + ", ".join(unplaced)


def test_imports_run_only_downwards() -> None:
    wrong = []
    for module, path in _modules():
        unit = _unit_of(module)
        for imported in set(_imports(module, path)):
            if imported.split(".")[0] not in TOP_PACKAGES:
                continue
            target = _unit_of(imported)
            if target in PACKAGE_ROOTS:  # "from tiago_description import transforms" names the unit too
                continue
            if target != unit and target not in ALLOWED.get(unit, PACKAGE_ROOTS.get(unit, set())):
                wrong.append(f"{module} imports {imported} ({unit} -> {target})")
    assert wrong == [], "imports against the layers:\n" + "\n".join(sorted(wrong))


def test_units_keep_away_from_the_libraries_of_other_layers() -> None:
    wrong = []
    for module, path in _modules():
        forbidden = FORBIDDEN_LIBRARIES.get(_unit_of(module), set())
        for imported in set(_imports(module, path)):
            if imported.split(".")[0] in forbidden:
                wrong.append(f"{module} imports {imported}")
    assert wrong == [], "\n".join(sorted(wrong))


def test_no_hand_written_module_passes_the_length_a_reader_takes_in_one_sitting() -> None:
    long = [
        f"{module} ({lines} lines)"
        for module, path in _modules()
        if (lines := len(path.read_text().splitlines())) > MAX_MODULE_LINES
    ]
    assert long == [], f"modules over {MAX_MODULE_LINES} lines: " + ", ".join(long)
