"""Start the digital twin: the simulated TIAGo++ and the robot's skills on one ROS 2 node.

    python -m tiago_twin --world FILE [--seed N] [--realtime-factor-cap X]
        [--idle-realtime-factor X] [--disturbance-seed N] [--robot-interfaces | --ros-adapter] ...

Why one module: it is the one place that knows both sides. The simulator (tiago_sim.sim_node)
plays the hardware and the vendor's stack and offers the hardware port; the skills
(tiago_skills.skills_node) get that port and nothing else. A real TIAGo++ runs the same skills
with an adapter on its own ROS 2 interfaces in place of the simulator.
Threads: the sim thread owns PyBullet; a MultiThreadedExecutor spins the node on the main thread.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node

from lab_description.world import DEFAULT_WORLD, World, WorldError, load_world, with_stock_sensors
from tiago_description.motion_library import DEFAULT_MOTIONS_FILE, load_motions
from tiago_sim.measuring.run_recorder import RunRecorder
from tiago_sim.node_main import spin_node, stacks_on_sigusr1
from tiago_sim.sim_node.hardware import SimulatedHardware
from tiago_sim.sim_node.navigation import Navigation
from tiago_sim.sim_node.node import SimNode, make_simulation, robot_world
from tiago_sim.sim_node.sim_thread import SimThread
from tiago_skills.perception.aruco import detect_marker, draw_detection
from tiago_skills.skills_node import RobotSkills
from tiago_twin.lab_reset import LabReset

log = logging.getLogger("tiago_twin")

INVALID_WORLD_EXIT_CODE = 2
ADAPTER_PACE = 5.0
ADAPTER_MAX_PACE = 10.0
"""The adapter renews velocity commands every 0.05 s of wall time and a command lapses after 0.5 s
of robot time (tiago_ros_hardware.base_loops): the robot may run at most ten times the wall."""
"""Exit code for a world file that does not validate; the reason is the last line on stderr."""


def outline_marker(world: World) -> Callable[[np.ndarray, np.ndarray, Any], np.ndarray]:
    """A recorded head frame with the first station marker the robot's detector finds outlined."""

    def annotate(rgb: np.ndarray, depth: np.ndarray, intrinsics: Any) -> np.ndarray:
        for station in world.stations:
            observation = detect_marker(rgb, intrinsics, station.marker_id, station.marker_size, depth)
            if observation is not None:
                return draw_detection(rgb, observation, intrinsics)
        return rgb

    return annotate


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m tiago_twin", description=__doc__.split("\n")[0])
    parser.add_argument("--world", type=Path, default=DEFAULT_WORLD, help="world YAML (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=None, help="seed for odometry noise and IK restarts")
    parser.add_argument(
        "--realtime-factor-cap",
        type=float,
        default=None,
        help="at most this many times real time (default: none)",
    )
    parser.add_argument(
        "--idle-realtime-factor",
        type=float,
        default=1.0,
        help="times real time while no motion runs (default: %(default)s)",
    )
    parser.add_argument("--motions", type=Path, default=DEFAULT_MOTIONS_FILE, help="keyframe motions YAML")
    parser.add_argument(
        "--disturbance-seed", type=int, default=None, help="seed of tiago_sim.measuring.disturbances"
    )
    parser.add_argument("--disturbance-levels", default="", help="DisturbanceLevels JSON")
    parser.add_argument("--record-dir", type=Path, default=None, help="save camera frames here")
    parser.add_argument(
        "--robot-interfaces",
        action="store_true",
        help="also serve a TIAGo++'s own ROS 2 interfaces (the controllers' FollowJointTrajectory, "
        "the base's velocity command, Nav2's navigate_to_pose), for software written against a robot",
    )
    parser.add_argument(
        "--ros-adapter",
        action="store_true",
        help="the skills reach the simulated robot through its own ROS 2 interfaces (tiago_ros_hardware), "
        f"as they would a real TIAGo++; serves them, and paces motion at {ADAPTER_PACE:g} times real time "
        f"at most unless --realtime-factor-cap says otherwise (at most {ADAPTER_MAX_PACE:g})",
    )
    parser.add_argument(
        "--stock-sensors",
        action="store_true",
        help="the lab has none of the lab-added plate sensors (the world file's `sensors` all off)",
    )
    parser.add_argument("--log-level", default="INFO")
    parser.add_argument(
        "--near-misses",
        action="store_true",
        help="log robot parts passing within 1 cm of the lab (measuring)",
    )
    args = parser.parse_args(argv)
    if args.ros_adapter:
        args.robot_interfaces = True
        args.realtime_factor_cap = args.realtime_factor_cap or ADAPTER_PACE
        if args.realtime_factor_cap > ADAPTER_MAX_PACE:
            parser.error(f"--ros-adapter needs --realtime-factor-cap at most {ADAPTER_MAX_PACE:g}")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    stacks_on_sigusr1()
    logging.basicConfig(level=args.log_level, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    try:
        world = load_world(args.world)
    except WorldError as error:
        # One line (a problem per line otherwise) that a parent process can show as it is.
        sys.stderr.write(f"invalid world file: {'; '.join(error.problems)}\n")
        return INVALID_WORLD_EXIT_CODE
    if args.stock_sensors:
        world = with_stock_sensors(world)
    log.info("lab-added plate sensors: %s", ", ".join(world.sensors.names()) or "none (a stock TIAGo++)")
    from tiago_sim.physics.simulation import (
        Simulation,  # heavy import (PyBullet), only in the process that owns it
    )

    def simulation() -> Any:
        sim = make_simulation(Simulation, world, args)
        if args.record_dir is not None:
            RunRecorder(sim, world, args.record_dir, annotate=outline_marker(world))
        return sim

    sim_thread = SimThread(
        simulation,
        realtime_factor_cap=args.realtime_factor_cap,
        idle_realtime_factor=args.idle_realtime_factor,
    )

    built: list[SimNode] = []

    def build(node: Node) -> SimNode:
        sim_thread.start()
        believed = robot_world(world, args)
        navigation = Navigation(node, believed, sim_thread)
        hardware: Any = SimulatedHardware(sim_thread, navigation)
        if args.ros_adapter:  # imported here: the robot's interface packages are built by ./run only
            from tiago_ros_hardware.hardware import RosHardware

            hardware = RosHardware(node)
            log.info("the skills reach the robot through its own ROS 2 interfaces (tiago_ros_hardware)")
        skills = RobotSkills(
            node,
            believed,
            hardware,
            args.motions,
            seed=args.seed if args.seed is not None else args.disturbance_seed,
            motion_time=lambda: sim_thread.busy_sim_s,
        )
        sim_node = SimNode(
            node,
            believed,
            sim_thread,
            navigation=navigation,
            pois=skills.current_pois,
            activity=skills.actions.activity.snapshot,
            activity_signature=skills.actions.activity.signature,
        )
        built.append(sim_node)
        if args.robot_interfaces:  # kept with the node: its action servers live as long
            from tiago_sim.sim_node.robot_interfaces import RobotInterfaces

            sim_node.robot_interfaces = RobotInterfaces(
                node,
                believed,
                sim_thread,
                navigation,
                sim_node.publishers.localisation_topics,
                load_motions(args.motions),
            )
        lab_reset = LabReset(node, sim_thread, skills.actions.slot)
        lab_reset.hooks += [sim_node.forget_the_old_lab, skills.forget]
        log.info("sim node ready: world %s, %d stations", world.source, len(world.stations))
        return sim_node

    def shut_down() -> None:
        sim_thread.stop()
        for sim_node in built:  # what localisation cost the sim thread, beside its own figures
            sim_node.localisation.log_cost()
            if sim_node.robot_interfaces is not None:
                sim_node.robot_interfaces.log_use()

    # Over the adapter, a skill's goal waits on controller goals and readings served by this same
    # node: each waiting goal holds a thread.
    threads = 16 if args.ros_adapter else 8
    return spin_node(
        "tiago_sim", lambda: MultiThreadedExecutor(num_threads=threads), build, before_shutdown=shut_down
    )
