"""The arm's way to the nest beside a station's marker board passes clear of the board, the bench and
the plate in the nest, on real physics.

Why: in random layout 132035 the empty gripper's joint-space move from "Benchtop" to the approach
of the nest beside the board swept a finger 2.3 mm into the board (COLLISION), and in 132040 and
132016 the wrist and a held plate met it; in 181006 a joint-space move to the approach above a plate
pushed that plate out of its nest. The skills now plan their ways first and check them with
the robot model's collision shapes (tiago_skills.bench_route, tiago_description.arm_clearance).
The fixture is 132035's station alone; the test stands in for perception only: it places the board
where the robot's pose estimate and the world file put it.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from lab_description.world import World, load_world
from tests.tiago_sim.sim_node.test_fold_from_hotel import behaviours, benchtop_joints
from tiago_description import transforms as tf
from tiago_description.arm_clearance import ArmClearance, Box, HeldBox
from tiago_description.kinematics import RobotKinematics
from tiago_description.motion_library import load_motions
from tiago_sim.physics.simulation import Simulation
from tiago_skills.bench_route import (
    WAY_CLEARANCE_M,
    BenchRoute,
    bench_box,
    board_box,
    largest_labware,
    nest_labware_boxes,
    station_boxes,
)
from tiago_skills.grasp_twins import FLIP_ABOUT_APPROACH

FIXTURE = Path(__file__).parent / "fixtures" / "board_beside_the_row.yaml"
ARM = "right"
NEST = 3  # beside the board
TOOL_SPEED = 0.35
PLATE = "plate_001"  # in nest 3


@pytest.fixture(scope="module")
def world() -> World:
    return load_world(FIXTURE)


@pytest.fixture
def sim(world: World) -> Iterator[Simulation]:
    sim = Simulation(world, seed=1)
    try:
        assert sim.run(sim.undock()).success
        assert sim.run(sim.move_joints(benchtop_joints())).success
        yield sim
    finally:
        sim.close()


def T_base_world(sim: Simulation) -> np.ndarray:
    x, y, yaw = sim.pose_estimate()
    return tf.invert(tf.from_planar(x, y, yaw))


def seen_marker(world: World, sim: Simulation) -> np.ndarray:
    """T_base_marker as a perfect sighting gives it: the world file's marker in the robot's base frame
    from its pose estimate (the test stands in for perception)."""
    return T_base_world(sim) @ world.station("labeler").T_world_marker()


def approach_targets(world: World, sim: Simulation) -> list[np.ndarray]:
    """The grasp pose above nest 3 and its twin with the fingers swapped, as the skills aim them."""
    station = world.station("labeler")
    T_base_approach = T_base_world(sim) @ station.T_world_marker() @ station.T_marker_site_approach(NEST)
    T_grasp = T_base_approach @ load_motions().hotel.T_slot_grasp(approach=False)
    return [T_grasp, T_grasp @ FLIP_ABOUT_APPROACH]


def run_way(sim: Simulation, trajectories) -> list:  # noqa: ANN001
    return [sim.run(sim.execute_trajectory(trajectory), timeout_s=60.0) for trajectory in trajectories]


def labware_boxes(world: World, sim: Simulation) -> list[Box]:
    """Every nest of the station as the skills count it when they come for a plate: stocked."""
    station = world.station("labeler")
    size = largest_labware(list(world.labware_types.values()))
    return nest_labware_boxes(station, seen_marker(world, sim), [1, 2, 3], size)


def way_boxes(world: World, sim: Simulation) -> list[Box]:
    return station_boxes(world.station("labeler"), seen_marker(world, sim)) + labware_boxes(world, sim)


def plate_shift_m(sim: Simulation, before: np.ndarray) -> float:
    return float(np.linalg.norm(sim.plate_bottom_pose(PLATE)[:3, 3] - before[:3, 3]))


def test_a_joint_space_move_the_model_refuses_touches_the_station_in_physics(
    world: World, sim: Simulation
) -> None:
    """The scenario is real: a joint-space move to an IK solution, as the skills used to make them,
    crosses the board or the bench by the model's collision shapes, and the physics agrees."""
    route = BenchRoute(behaviours(seed=0))
    start = sim.joint_positions()
    station = world.station("labeler")
    boxes = {  # the model's names and the simulator's
        "marker stand": board_box(station, seen_marker(world, sim)),
        "table": bench_box(station, seen_marker(world, sim)),
    }
    targets = approach_targets(world, sim)
    ways = []  # the joint-space moves, tried second (the later ways are not planned)
    for _index, way in route.ways(ARM, start, targets, TOOL_SPEED, list(boxes.values()), None):
        name = way.split(":")[0] if isinstance(way, str) else way.name
        if name not in ("straight line", "joint-space move"):
            break
        if name == "joint-space move" and not isinstance(way, str):
            ways.append(way)

    def crossed(way) -> set[str]:  # noqa: ANN001
        path = list(way.path)
        return {
            name
            for name, box in boxes.items()
            if route.behaviours.planning.clearance(ARM, start, path, [box], None).distance_m < 0
        }

    way = next((way for way in ways if crossed(way)), None)
    assert way is not None, "every joint-space move passes clear here: the fixture lost its point"
    outcome = run_way(sim, way.trajectories)[-1]
    assert outcome.error_code == "COLLISION", outcome.message
    assert any(f"touched labeler {name}" in outcome.message for name in crossed(way)), outcome.message


def test_a_joint_space_move_through_the_plate_in_the_nest_pushes_it_in_physics(
    world: World, sim: Simulation
) -> None:
    """The scenario of the labware boxes is real: a joint-space move to the approach above the plate
    it comes for, clear of the board and the bench but through the plate by the model, moves the
    plate in physics (in random layout 181006 it left its nest, and the descent to grasp it stopped
    short)."""
    route = BenchRoute(behaviours(seed=0))
    start = sim.joint_positions()
    station = station_boxes(world.station("labeler"), seen_marker(world, sim))
    labware = labware_boxes(world, sim)
    through = None
    for _index, way in route.ways(
        ARM, start, approach_targets(world, sim), TOOL_SPEED, station + labware, None
    ):
        if isinstance(way, str) or way.name != "joint-space move":
            continue
        path = list(way.path)
        if (
            route.behaviours.planning.clearance(ARM, start, path, labware, None).distance_m < -0.01
            and route.behaviours.planning.clearance(ARM, start, path, station, None).distance_m > 0
        ):
            through = way
            break
    assert through is not None, "no joint-space move crosses the plate alone here: the fixture lost its point"
    before = sim.plate_bottom_pose(PLATE)
    run_way(sim, through.trajectories)
    assert plate_shift_m(sim, before) > 0.002
    pushed = sim.plate_pushes.pushes  # the simulation says so, naming the link that pushed
    assert pushed and pushed[0].plate == PLATE and pushed[0].link.startswith(f"gripper_{ARM}"), pushed


def test_the_planned_way_reaches_the_nest_s_approach_and_touches_nothing(
    world: World, sim: Simulation
) -> None:
    route = BenchRoute(behaviours(seed=0))
    targets = approach_targets(world, sim)
    boxes = way_boxes(world, sim)
    before = sim.plate_bottom_pose(PLATE)
    start = sim.joint_positions()
    index, way = route.plan(ARM, start, targets, TOOL_SPEED, boxes, None)
    assert (
        route.behaviours.planning.clearance(ARM, start, list(way.path), boxes, None).distance_m
        >= WAY_CLEARANCE_M
    )
    for outcome in run_way(sim, way.trajectories):
        assert outcome.success, f"{way.name}: {outcome.error_code} {outcome.message}"
    reached = RobotKinematics().forward(sim.joint_positions(), f"gripper_{ARM}_grasping_frame")
    assert np.linalg.norm(reached[:3, 3] - targets[index][:3, 3]) < 0.005
    assert plate_shift_m(sim, before) < 0.0005 and sim.plate_pushes.pushes == []


def test_the_way_around_keeps_clear_of_the_station_and_the_robot_in_physics(
    world: World, sim: Simulation
) -> None:
    """The last way, searched in joint space (tiago_skills.joint_rrt), asked for directly here: it
    reaches the target and touches nothing; its path keeps the clearance from the body too."""
    route = BenchRoute(behaviours(seed=0))
    boxes = way_boxes(world, sim)
    start = sim.joint_positions()
    target = approach_targets(world, sim)[0]
    way = route._around(ARM, start, target, boxes, None)
    assert not isinstance(way, str), way
    clearance = ArmClearance(RobotKinematics())
    assert clearance.nearest(ARM, start, list(way.path), boxes).distance_m >= WAY_CLEARANCE_M - 0.001
    assert clearance.nearest(ARM, start, list(way.path), [], body=True).distance_m > 0.01
    for outcome in run_way(sim, way.trajectories):
        assert outcome.success, f"{way.name}: {outcome.error_code} {outcome.message}"
    reached = RobotKinematics().forward(sim.joint_positions(), f"gripper_{ARM}_grasping_frame")
    assert np.linalg.norm(reached[:3, 3] - target[:3, 3]) < 0.005


def test_the_clearance_counts_the_held_plate_and_sees_an_overlap() -> None:
    """Model only: a box just beside the grasping frame is 3 cm from the fingers' pads but inside a
    held plate; a box 3 m ahead of the base is well over 1 m away."""
    kinematics = RobotKinematics()
    clearance = ArmClearance(kinematics)
    joints = benchtop_joints()
    T_tool = kinematics.forward(joints, f"gripper_{ARM}_grasping_frame")
    # along the grasp z axis (the pads' width, the plate's long side): pads reach 40 mm, a plate 64 mm
    beside = Box("beside", (0.01, 0.01, 0.01), T_tool @ tf.make_transform((0.0, 0.0, 0.055)))
    far = Box("far", (0.01, 0.01, 0.01), tf.make_transform((3.0, 0.0, 1.0)))
    plate = HeldBox((0.0144, 0.0855, 0.1278), tf.make_transform((0.012 - 0.0072, 0.0, 0.0)))
    empty = clearance.nearest(ARM, joints, [joints], [beside])
    held = clearance.nearest(ARM, joints, [joints], [beside], plate)
    assert 0.005 < empty.distance_m < 0.02, empty.describe()
    assert held.distance_m < 0 and held.link == "held plate", held.describe()
    assert clearance.nearest(ARM, joints, [joints], [far]).distance_m > 1.0
