"""Collision honesty in real PyBullet: a drive through a bench, or into the dock front first, is
stopped and named; a drive around the bench, and docking, touch nothing they should not."""

from __future__ import annotations

import math

import pybullet as p
import pytest

from lab_description.world import DEFAULT_WORLD, load_world
from tiago_sim.navigation.occupancy_map import build_map
from tiago_sim.navigation.planner import ROBOT_RADIUS_M, GlobalPlanner
from tiago_sim.physics.collision_watch import COLLISION, NEAR_MISS_PERIOD_S
from tiago_sim.physics.simulation import Simulation

WORLD = DEFAULT_WORLD.parent / "bench_in_the_way.yaml"


@pytest.fixture(scope="module")
def lab() -> tuple[Simulation, GlobalPlanner]:
    world = load_world(WORLD)
    sim = Simulation(world, seed=4)
    yield sim, GlobalPlanner(build_map(world))
    sim.close()


def go(sim: Simulation, planner: GlobalPlanner, poi: str) -> None:
    goal = sim.world.pois[poi]
    motion = sim.run(sim.follow_path(planner.plan(sim.pose_estimate(), (goal.x, goal.y, goal.yaw)), goal.yaw))
    assert motion.success, motion.message
    x, y, yaw = sim.robot.base_xy_yaw()
    assert math.hypot(x - goal.x, y - goal.y) < 0.03 and abs(yaw - goal.yaw) < 0.03


def test_around_the_bench_and_onto_the_dock_nothing_is_touched(lab: tuple[Simulation, GlobalPlanner]) -> None:
    sim, planner = lab
    assert sim.run(sim.undock()).success
    for poi in ("station_a_work", "station_b_work", "station_a_work"):
        go(sim, planner, poi)
    docking = sim.run(sim.dock())
    assert docking.success and sim.is_docked(), docking.message
    assert sim.run(sim.undock()).success
    assert sim.collision_watch.collisions == []


def test_a_straight_drive_through_the_bench_is_stopped_as_a_collision(
    lab: tuple[Simulation, GlobalPlanner],
) -> None:
    sim, planner = lab
    go(sim, planner, "station_a_work")
    goal = sim.world.pois["station_b_work"]
    motion = sim.run(sim.drive_to(goal.x, goal.y, goal.yaw))  # planning bypassed: straight at B
    assert not motion.success and motion.error_code == COLLISION
    assert "touched obstacle bench_c" in motion.message and "mm deep" in motion.message
    first = sim.collision_watch.collisions[0]  # the first step in contact may bring several links
    assert first.text() in motion.message
    assert {c.thing for c in sim.collision_watch.collisions} == {"obstacle bench_c"}
    assert all(
        c.depth_m < 0.03 and abs(c.sim_time - first.sim_time) < 0.05 for c in sim.collision_watch.collisions
    )
    for _ in range(240):  # the base brakes and stands; it does not push on through the bench
        sim.step()
    bench = sim.world.obstacles[0]
    x, y, _ = sim.robot.base_xy_yaw()
    assert bench.distance_to(x, y) > 0.15, "the base centre went on into the bench"
    assert sim.base.stopped()


def test_the_base_driving_into_the_dock_front_first_is_a_collision() -> None:
    """The base touches the dock by design with its back only (the charging contacts): a drive back
    to the docked pose facing the dock meets it with the base's front and is stopped as a collision."""
    world = load_world(DEFAULT_WORLD)
    sim = Simulation(world, seed=2)
    assert sim.run(sim.undock()).success
    dock = world.dock_pose
    motion = sim.run(sim.drive_to(dock.x, dock.y, dock.yaw + math.pi, speed=0.1))
    sim.close()
    assert not motion.success and motion.error_code == COLLISION, motion.message
    assert "the base (base_footprint) touched the dock" in motion.message


def test_the_travel_pose_sweeps_no_farther_than_the_planners_robot_radius() -> None:
    """A thin upright plate probed around the robot at 72 bearings: the nearest robot point's
    distance from the base centre is the radius the robot sweeps when it turns in place."""
    sim = Simulation(load_world(DEFAULT_WORLD), seed=1)  # docked, arms in Travel, torso at 0.15 m
    client = sim.client_id
    x, y, _ = sim.robot.base_xy_yaw()
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.005, 0.02, 1.0], physicsClientId=client)
    plate = p.createMultiBody(0.0, shape, -1, [0.0, 0.0, 1.0], physicsClientId=client)
    reach = []
    for k in range(72):
        bearing = 2 * math.pi * k / 72
        position = [x + 1.5 * math.cos(bearing), y + 1.5 * math.sin(bearing), 1.0]
        orientation = p.getQuaternionFromEuler([0.0, 0.0, bearing])
        p.resetBasePositionAndOrientation(plate, position, orientation, physicsClientId=client)
        p.performCollisionDetection(physicsClientId=client)
        nearest = min(
            point[8] for point in p.getClosestPoints(sim.robot.id, plate, 2.0, physicsClientId=client)
        )
        reach.append(1.5 - 0.005 - nearest)
    sim.close()
    assert max(reach) <= ROBOT_RADIUS_M
    assert max(reach) > ROBOT_RADIUS_M - 0.02, (
        f"the planner's radius is {ROBOT_RADIUS_M - max(reach):.3f} m too big"
    )


def test_near_misses_when_asked_for_are_recorded_before_the_touch() -> None:
    world = load_world(WORLD)
    sim = Simulation(world, seed=5)
    sim.collision_watch.near_miss_period_s = NEAR_MISS_PERIOD_S
    planner = GlobalPlanner(build_map(world))
    assert sim.run(sim.undock()).success
    go(sim, planner, "station_a_work")
    goal = world.pois["station_b_work"]
    motion = sim.run(sim.drive_to(goal.x, goal.y, goal.yaw, speed=0.1))
    assert motion.error_code == COLLISION
    closest = sim.collision_watch.near_misses
    assert any(thing == "obstacle bench_c" and distance < 0.005 for (_, thing), distance in closest.items())
    sim.close()
