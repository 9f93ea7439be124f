"""The robot's skills on a ROS 2 node: the action servers, their parameters, the workcell service.

Why one place: the task sequencer and the bridge see the robot through these actions alone, and
the same wiring runs on the simulator's hardware (tiago_twin) and on a real TIAGo++ (an adapter
of robot_port on its ROS 2 interfaces). The lab comes from the world file as the robot believes it.

ROS parameters (changeable at runtime): ``pois.<name>`` = [x, y, yaw] (from the world file),
``stations.<name>.approach_height_m`` and ``speed_scale`` (0.05 .. 2.0).
Lives on: the node's executor threads.
"""

from __future__ import annotations

import dataclasses
from array import array
from collections.abc import Callable
from pathlib import Path
from typing import Any

from labware_interfaces.msg import StationInfo
from labware_interfaces.srv import DescribeWorkcell
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter

from lab_description.world import World
from robot_port.hardware import RobotHardware
from tiago_description.motion_library import load_motions
from tiago_skills.action_servers import RobotActionServers
from tiago_skills.behaviours import RobotBehaviours
from tiago_skills.marker_motion import MarkerMotionBehaviour


class RobotSkills:
    """The six robot-level action servers on `node`, driving `hardware`."""

    def __init__(
        self,
        node: Node,
        world: World,
        hardware: RobotHardware,
        motions_file: Path,
        *,
        seed: int | None = None,
        motion_time: Callable[[], float] = lambda: 0.0,
    ) -> None:
        self.node = node
        self.world = world
        for name, pose in world.pois.items():
            node.declare_parameter(f"pois.{name}", [pose.x, pose.y, pose.yaw])
        for station in world.stations:
            node.declare_parameter(f"stations.{station.name}.approach_height_m", station.approach_height)
        node.declare_parameter("speed_scale", 1.0)
        motions = load_motions(motions_file)
        self.behaviours = RobotBehaviours(
            poi_pose=lambda name: self.current_pois().get(name),
            poi_names=lambda: sorted(self.current_pois()),
            dock_poi=lambda: world.dock_poi,
            hotel_slots=world.hotel_slots,
            motions=motions,
            speed_scale=lambda: float(node.get_parameter("speed_scale").value),
            seed=seed,
            plate_widths=tuple(sorted({t.width for t in world.labware_types.values()})),
            # a drive to a station's POI raises the torso to the bench height (drive_posture)
            station_pois=frozenset(station.poi for station in world.stations),
            # ... and turns the head to its marker (the lab description's)
            marker_at_poi=lambda poi: next(
                (station.T_world_marker() for station in self.world.stations if station.poi == poi), None
            ),
        )
        self.marker_motion = MarkerMotionBehaviour(world, self.behaviours, motions.hotel)
        self.actions = RobotActionServers(
            node,
            hardware,
            navigate=self.behaviours.navigate,
            dock=self.behaviours.dock,
            undock=self.behaviours.undock,
            play_motion=self.behaviours.play_motion,
            marker_motion=self.marker_motion,
            gripper=self.behaviours.gripper,
            motion_time=motion_time,
        )
        node.create_service(DescribeWorkcell, "/describe_workcell", self._describe_workcell)
        node.add_on_set_parameters_callback(self._on_parameters)

    def current_pois(self) -> dict[str, tuple[float, float, float]]:
        pois = {}
        for name in self.world.pois:
            value = self.node.get_parameter(f"pois.{name}").value
            pois[name] = (float(value[0]), float(value[1]), float(value[2]))
        return pois

    def forget(self) -> None:
        """After a lab reset: no grasp remembered, no marker sighting, no error standing."""
        self.behaviours.grasp_flipped.clear()
        self.behaviours.twin_wanted.clear()
        self.behaviours.holding.clear()
        self.marker_motion.last_sighting = None
        self.marker_motion.nests.floors_seen.clear()
        self.actions.activity.clear()

    def _on_parameters(self, parameters: list[Parameter]) -> SetParametersResult:
        for parameter in parameters:
            name, value = parameter.name, parameter.value
            # a double array arrives over ROS as array.array, from a launch file as a list
            if name.startswith("pois.") and (not isinstance(value, (list, tuple, array)) or len(value) != 3):
                return SetParametersResult(successful=False, reason=f"{name} must be [x, y, yaw]")
            if name == "speed_scale" and not 0.05 <= float(value) <= 2.0:
                return SetParametersResult(successful=False, reason="speed_scale must be in 0.05 .. 2.0")
        for parameter in parameters:
            name = parameter.name
            if name.startswith("stations.") and name.endswith(".approach_height_m"):
                station_name = name[len("stations.") : -len(".approach_height_m")]
                stations = tuple(
                    dataclasses.replace(s, approach_height=float(parameter.value))
                    if s.name == station_name
                    else s
                    for s in self.world.stations
                )
                self.world = dataclasses.replace(self.world, stations=stations)
                self.marker_motion.world = self.world
        return SetParametersResult(successful=True)

    def _describe_workcell(self, _request: Any, response: Any) -> Any:
        workcell = self.world.describe_workcell()
        response.stations = [
            StationInfo(name=s.name, sub_positions=s.sub_positions, poi=s.poi) for s in workcell.stations
        ]
        response.hotel_slots = workcell.hotel_slots
        response.pois = list(workcell.pois)
        response.dock_poi = workcell.dock_poi
        response.nest_sensors = workcell.sensors.nests
        response.hotel_sensors = workcell.sensors.hotel
        response.label_readers = workcell.sensors.label_readers
        return response
