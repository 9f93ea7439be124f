"""The simulated TIAGo++'s node side: sensors, the navigation stand-in, faults and ground truth.

Owns nothing of the robot's software: the skills' action servers (tiago_skills) share the node
and reach the robot through the hardware port (hardware.SimulatedHardware); the start-up module
(tiago_twin) builds both. Threads: the sim thread (sim_thread.SimThread) owns the Simulation and
steps it; services and timers hand jobs to it and wait on futures. Offers the sensor topics
(publishers), /map, /global_costmap/costmap and /plan (navigation), /check_placement (ground
truth, for success checks only).

ROS parameters (changeable at runtime): ``realtime_factor_cap`` (0 = none),
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
import logging
from collections.abc import Callable
from typing import Any

from labware_interfaces.srv import CheckPlacement
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter

from lab_description.world import World
from labware_model.holders import UNKNOWN, Nest, location_text
from tiago_sim.measuring.fault_injection import Occluders, PlateFaults
from tiago_sim.measuring.path_blocker import PathBlocker, parse_block_path
from tiago_sim.sim_node.localisation import LocalisationLoop
from tiago_sim.sim_node.navigation import Navigation
from tiago_sim.sim_node.publishers import StatePublishers
from tiago_sim.sim_node.sim_thread import SimThread

log = logging.getLogger("tiago_sim.sim_node")

PLATE_FAULTS = ("fault.remove_plate", "fault.drop_plate", "fault.knock_plate")


class SimNode:
    """Wires the Simulation (on its thread) to ROS topics, services and parameters."""

    def __init__(
        self,
        node: Node,
        world: World,
        sim_thread: SimThread,
        *,
        navigation: Navigation,
        pois: Callable[[], dict[str, tuple[float, float, float]]],
        activity: Callable[[], Any],
        activity_signature: Callable[[], Any],
    ) -> None:
        self.node = node
        self.world = world
        self.sim_thread = sim_thread
        self.occluders = Occluders(world)
        self.plate_faults = PlateFaults()
        self.navigation = navigation
        self.robot_interfaces: Any = None  # a robot's own ROS interfaces, when the start-up serves them
        self.path_blocker = self._path_blocker()
        self._declare_parameters()
        # the robot's localisation: laser scans against the map of the world the robot believes
        self.localisation = sim_thread.run(lambda sim: LocalisationLoop(world, sim))
        self.publishers = StatePublishers(
            node,
            sim_thread,
            pois=pois,
            activity=activity,
            activity_signature=activity_signature,
            localisation=self.localisation,
        )
        node.create_service(CheckPlacement, "/check_placement", self._check_placement)
        node.add_on_set_parameters_callback(self._on_parameters)

    # -- parameters ------------------------------------------------------------------------
    def _declare_parameters(self) -> None:
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

    def forget_the_old_lab(self) -> None:
        """After a reset: localisation starts again at the dock on the new Simulation; no fault
        stands."""
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

    # -- services -------------------------------------------------------------------------
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


def make_simulation(simulation_class: Any, world: World, args: argparse.Namespace) -> Any:
    """The Simulation, built in the true (disturbed) world when a disturbance seed is given
    (``args``: the start-up's options, tiago_twin.startup)."""
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
