"""The simulated TIAGo++ as a ROS 2 node: the one process that owns PyBullet.

    python -m tiago_sim.sim_node --world FILE [--seed N] [--realtime-factor-cap X]
        [--idle-realtime-factor X]

Threads: the sim thread (sim_thread.SimThread) owns the Simulation and steps it; a
MultiThreadedExecutor spins the node on the main thread; action execute callbacks and timers only
hand jobs to the sim thread and wait on futures. Offers the robot-level actions (ros_actions),
the sensor topics (ros_publishers), /map, /global_costmap/costmap and /plan (navigation),
/describe_workcell and /check_placement (ground truth, for success checks only).

ROS parameters (changeable at runtime): ``pois.<name>`` = [x, y, yaw] (from the world YAML),
``stations.<name>.approach_height_m``, ``speed_scale``, ``realtime_factor_cap`` (0 = none),
``idle_realtime_factor``, and - for tests only, as fault injection (tiago_sim.measuring.fault_injection) -
``fault.occlude_marker``: a station name whose marker gets hidden behind a visual-only panel
(empty: none); ``fault.remove_plate``: a plate id taken away onto the floor far from every station;
``fault.drop_plate``: a plate id that slips out of the hotel during the next drive;
``fault.knock_plate``: a plate id taken away the moment the gripper releases it in a nest. Setting
any plate fault to empty puts faulted plates back at their world-file nests. ``fault.block_path``:
a box not on the map appears on the path during the next drive, "1.0" m ahead of the base, or
"closed" / "closed:1.5" as a floor-wide wall (tiago_sim.measuring.path_blocker); empty removes it.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import sys
from array import array
from pathlib import Path
from typing import Any

from labware_interfaces.msg import StationInfo
from labware_interfaces.srv import CheckPlacement, DescribeWorkcell
from rcl_interfaces.msg import SetParametersResult
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter

from labware_model.holders import UNKNOWN, Nest, location_text
from tiago_sim.lab.world import DEFAULT_WORLD, World, WorldError, load_world
from tiago_sim.measuring.fault_injection import Occluders, PlateFaults
from tiago_sim.measuring.path_blocker import PathBlocker, parse_block_path
from tiago_sim.node_main import spin_node
from tiago_sim.robot.motion_library import DEFAULT_MOTIONS_FILE, load_motions
from tiago_sim.sim_node.action_servers import RobotActionServers
from tiago_sim.sim_node.behaviours import RobotBehaviours
from tiago_sim.sim_node.lab_reset import LabReset
from tiago_sim.sim_node.localisation import LocalisationLoop
from tiago_sim.sim_node.marker_motion import MarkerMotionBehaviour
from tiago_sim.sim_node.navigation import Navigation
from tiago_sim.sim_node.publishers import StatePublishers
from tiago_sim.sim_node.sim_thread import SimThread

log = logging.getLogger("tiago_sim.sim_node")

PLATE_FAULTS = ("fault.remove_plate", "fault.drop_plate", "fault.knock_plate")
INVALID_WORLD_EXIT_CODE = 2
"""Exit code for a world file that does not validate; the reason is the last line on stderr."""


class SimNode:
    """Wires the Simulation (on its thread) to ROS topics, services and actions."""

    def __init__(self, node: Node, world: World, sim_thread: SimThread, motions_file: Path) -> None:
        self.node = node
        self.world = world
        self.sim_thread = sim_thread
        self.occluders = Occluders(world)
        self.plate_faults = PlateFaults()
        self.navigation = Navigation(node, world)
        self.path_blocker = self._path_blocker()
        self._declare_parameters()
        motions = load_motions(motions_file)
        self.behaviours = RobotBehaviours(
            poi_pose=self.poi_pose,
            poi_names=lambda: sorted(self.current_pois()),
            dock_poi=lambda: world.dock_poi,
            hotel_slots=world.hotel_slots,
            motions=motions,
            speed_scale=lambda: float(node.get_parameter("speed_scale").value),
            navigation=self.navigation,
        )
        self.marker_motion = MarkerMotionBehaviour(world, self.behaviours, motions.hotel)
        self.actions = RobotActionServers(
            node,
            sim_thread,
            navigate=self.behaviours.navigate,
            dock=self.behaviours.dock,
            undock=self.behaviours.undock,
            play_motion=self.behaviours.play_motion,
            marker_motion=self.marker_motion,
            gripper=self.behaviours.gripper,
        )
        # the robot's localisation: laser scans against the map of the world the robot believes
        self.localisation = sim_thread.run(lambda sim: LocalisationLoop(world, sim))
        self.publishers = StatePublishers(
            node,
            sim_thread,
            pois=self.current_pois,
            activity=self.actions.activity.snapshot,
            activity_signature=self.actions.activity.signature,
            localisation=self.localisation,
        )
        self.lab_reset = LabReset(node, sim_thread, self.actions.slot)
        self.lab_reset.hooks.append(self._forget_the_old_lab)
        node.create_service(DescribeWorkcell, "/describe_workcell", self._describe_workcell)
        node.create_service(CheckPlacement, "/check_placement", self._check_placement)
        node.add_on_set_parameters_callback(self._on_parameters)

    # -- parameters ------------------------------------------------------------------------
    def _declare_parameters(self) -> None:
        for name, pose in self.world.pois.items():
            self.node.declare_parameter(f"pois.{name}", [pose.x, pose.y, pose.yaw])
        for station in self.world.stations:
            self.node.declare_parameter(f"stations.{station.name}.approach_height_m", station.approach_height)
        self.node.declare_parameter("speed_scale", 1.0)
        self.node.declare_parameter("realtime_factor_cap", float(self.sim_thread.realtime_factor_cap or 0.0))
        self.node.declare_parameter("idle_realtime_factor", float(self.sim_thread.idle_realtime_factor))
        self.node.declare_parameter("fault.occlude_marker", "")
        self.node.declare_parameter("fault.remove_plate", "")
        self.node.declare_parameter("fault.drop_plate", "")
        self.node.declare_parameter("fault.knock_plate", "")
        self.node.declare_parameter("fault.block_path", "")

    def _on_parameters(self, parameters: list[Parameter]) -> SetParametersResult:
        for parameter in parameters:
            name, value = parameter.name, parameter.value
            # a double array arrives over ROS as array.array, from a launch file as a list
            if name.startswith("pois.") and (not isinstance(value, (list, tuple, array)) or len(value) != 3):
                return SetParametersResult(successful=False, reason=f"{name} must be [x, y, yaw]")
            if name == "speed_scale" and not 0.05 <= float(value) <= 2.0:
                return SetParametersResult(successful=False, reason="speed_scale must be in 0.05 .. 2.0")
            if (
                name == "fault.occlude_marker"
                and value
                and value not in {s.name for s in self.world.stations}
            ):
                return SetParametersResult(successful=False, reason=f"unknown station {value!r}")
            if name == "fault.block_path":
                try:
                    parse_block_path(str(value))
                except ValueError as error:
                    return SetParametersResult(successful=False, reason=str(error))
            plates = {plate.labware_id for plate in self.world.plates}
            if name in PLATE_FAULTS and value and value not in plates:
                return SetParametersResult(successful=False, reason=f"unknown plate {value!r}")
        for parameter in parameters:
            self._apply(parameter.name, parameter.value)
        return SetParametersResult(successful=True)

    def _apply(self, name: str, value: Any) -> None:
        if name == "realtime_factor_cap":
            self.sim_thread.realtime_factor_cap = float(value) if value and float(value) > 0 else None
        elif name == "idle_realtime_factor":
            self.sim_thread.idle_realtime_factor = float(value)
        elif name == "fault.occlude_marker":
            station = str(value)
            self.sim_thread.call(lambda sim: self.occluders.set_occluded(sim, station))
        elif name == "fault.block_path":
            self.sim_thread.run(lambda sim: self._apply_block_path(sim, str(value)))
        elif name in PLATE_FAULTS:
            self.sim_thread.run(lambda sim: self._apply_plate_fault(sim, name, str(value)))
        elif name.startswith("stations.") and name.endswith(".approach_height_m"):
            station_name = name[len("stations.") : -len(".approach_height_m")]
            stations = tuple(
                dataclasses.replace(s, approach_height=float(value)) if s.name == station_name else s
                for s in self.world.stations
            )
            self.world = dataclasses.replace(self.world, stations=stations)
            self.marker_motion.world = self.world

    def _apply_plate_fault(self, sim: Any, name: str, labware_id: str) -> None:
        if not labware_id:
            self.plate_faults.restore(sim)
        elif name == "fault.remove_plate":
            self.plate_faults.remove(sim, labware_id)
        elif name == "fault.knock_plate":
            self.plate_faults.arm_knock(sim, labware_id)
            self.sim_thread.watch(self.plate_faults.knock_if_released)
        else:
            self.plate_faults.arm_drop(sim, labware_id)
            # Checked after every batch of steps: a wall-clock timer could miss a fast drive (seen
            # under CI load: a 1 s drive went by without the check seeing the base at speed).
            self.sim_thread.watch(self.plate_faults.drop_if_driving)

    def _path_blocker(self) -> PathBlocker:
        return PathBlocker(self.world.floor_size, lambda: self.navigation.last_plan)

    def _apply_block_path(self, sim: Any, value: str) -> None:
        request = parse_block_path(value)
        if request is None:
            self.path_blocker.clear(sim)
            return
        self.path_blocker.arm(sim, request)
        self.sim_thread.watch(self.path_blocker.watch)

    def _forget_the_old_lab(self) -> None:
        """After a reset: localisation starts again at the dock on the new Simulation; no fault
        stands, no grasp is remembered, no error shows."""
        self.localisation = self.sim_thread.run(lambda sim: LocalisationLoop(self.world, sim))
        self.publishers.localisation = self.localisation
        self.occluders = Occluders(self.world)
        self.plate_faults = PlateFaults()
        self.path_blocker.request, self.path_blocker.body = None, -1  # its box went with the old Simulation
        self.path_blocker = self._path_blocker()
        self.node.set_parameters(
            [
                Parameter("fault.occlude_marker", value=""),
                Parameter("fault.block_path", value=""),
                *(Parameter(name, value="") for name in PLATE_FAULTS),
            ]
        )
        self.behaviours.grasp_flipped.clear()
        self.behaviours.holding.clear()
        self.marker_motion.last_sighting = None
        self.actions.activity.clear()

    def current_pois(self) -> dict[str, tuple[float, float, float]]:
        pois = {}
        for name in self.world.pois:
            value = self.node.get_parameter(f"pois.{name}").value
            pois[name] = (float(value[0]), float(value[1]), float(value[2]))
        return pois

    def poi_pose(self, name: str) -> tuple[float, float, float] | None:
        return self.current_pois().get(name)

    # -- services -------------------------------------------------------------------------
    def _describe_workcell(self, _request: Any, response: Any) -> Any:
        workcell = self.world.describe_workcell()
        response.stations = [
            StationInfo(name=s.name, sub_positions=s.sub_positions, poi=s.poi) for s in workcell.stations
        ]
        response.hotel_slots = workcell.hotel_slots
        response.pois = list(workcell.pois)
        response.dock_poi = workcell.dock_poi
        return response

    def _check_placement(self, request: Any, response: Any) -> Any:
        """Ground truth about a plate; an empty station asks about no nest."""
        try:
            nest = Nest(request.station, int(request.sub_position)) if request.station else None
            check = self.sim_thread.run(lambda sim: sim.check_placement(request.labware_id, nest))
        except Exception as error:  # noqa: BLE001 - answer "unknown" rather than fail the call
            log.warning("check_placement failed: %s", error)
            response.found, response.location = False, location_text(UNKNOWN)
            return response
        response.found = bool(check.found)
        response.in_nest = bool(check.in_nest)
        response.position_error_m = float(check.position_error_m)
        response.yaw_error_rad = float(check.yaw_error_rad)
        response.location = location_text(check.location)
        response.outside = str(check.outside)
        return response


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m tiago_sim.sim_node", description=__doc__.split("\n")[0])
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
    parser.add_argument("--log-level", default="INFO")
    parser.add_argument(
        "--near-misses",
        action="store_true",
        help="log robot parts passing within 1 cm of the lab (measuring)",
    )
    return parser.parse_args(argv)


def make_simulation(simulation_class: Any, world: World, args: argparse.Namespace) -> Any:
    """The Simulation, built in the true (disturbed) world when a disturbance seed is given."""
    if args.disturbance_seed is None:
        sim = simulation_class(world, seed=args.seed)
    else:
        from tiago_sim.measuring import disturbances

        disturbance = disturbances.draw(world, args.disturbance_seed, _levels(args))
        sim = simulation_class(
            disturbances.true_world(world, disturbance),
            seed=args.disturbance_seed if args.seed is None else args.seed,
            odometry_noise=disturbance.levels.odometry_noise,
        )
        disturbances.apply_to_simulation(sim, disturbance)
    if getattr(args, "near_misses", False):
        from tiago_sim.physics.collision_watch import NEAR_MISS_PERIOD_S

        sim.collision_watch.near_miss_period_s = NEAR_MISS_PERIOD_S
    if args.record_dir is not None:
        from tiago_sim.measuring.run_recorder import RunRecorder

        RunRecorder(sim, world, args.record_dir)
    return sim


def robot_world(world: World, args: argparse.Namespace) -> World:
    """What the robot's behaviours believe: nominal, with POIs where navigation really stops."""
    if args.disturbance_seed is None:
        return world
    from tiago_sim.measuring import disturbances

    return disturbances.believed_world(world, disturbances.draw(world, args.disturbance_seed, _levels(args)))


def _levels(args: argparse.Namespace) -> Any:
    from tiago_sim.measuring.disturbances import DisturbanceLevels

    levels_json = args.disturbance_levels
    return DisturbanceLevels.from_json(levels_json) if levels_json else DisturbanceLevels()


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    logging.basicConfig(level=args.log_level, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    try:
        world = load_world(args.world)
    except WorldError as error:
        # One line (a problem per line otherwise) that a parent process can show as it is.
        sys.stderr.write(f"invalid world file: {'; '.join(error.problems)}\n")
        return INVALID_WORLD_EXIT_CODE
    from tiago_sim.physics.simulation import (
        Simulation,  # heavy import (PyBullet), only in the process that owns it
    )

    sim_thread = SimThread(
        lambda: make_simulation(Simulation, world, args),
        realtime_factor_cap=args.realtime_factor_cap,
        idle_realtime_factor=args.idle_realtime_factor,
    )

    built: list[SimNode] = []

    def build(node: Node) -> SimNode:
        sim_thread.start()
        sim_node = SimNode(node, robot_world(world, args), sim_thread, args.motions)
        built.append(sim_node)
        log.info("sim node ready: world %s, %d stations", world.source, len(world.stations))
        return sim_node

    def shut_down() -> None:
        sim_thread.stop()
        for sim_node in built:  # what localisation cost the sim thread, beside its own figures
            sim_node.localisation.log_cost()

    return spin_node(
        "tiago_sim", lambda: MultiThreadedExecutor(num_threads=8), build, before_shutdown=shut_down
    )
