"""A TIAGo++'s own ROS 2 interfaces, served by the simulator when asked (tiago_twin --robot-interfaces).

Why: the skills reach the twin through the hardware port in-process, the fast way campaigns need;
software written against a real robot (and the port's ROS adapter) speaks the robot's interfaces
instead (robot_port.tiago_interfaces). These are the ones the sensor topics do not already give:
the controllers' actions (controllers), named motions (play_motion), the base's velocity input,
Nav2's navigation goal and its planner, the docking a lab adds (base_interfaces), localisation's
map -> odom on /tf and the robot model's fixed frames on /tf_static (tf_topic). Off by default:
their endpoints cost discovery and CPU in every trial.
"""

from __future__ import annotations

import logging

from rclpy.node import Node

from lab_description.world import World
from tiago_description.fixed_frames import fixed_frames
from tiago_description.motion_library import MotionLibrary
from tiago_description.robot_model import build_urdf
from tiago_sim.sim_node.base_interfaces import (
    BaseVelocityInput,
    ComputePathToPoseServer,
    DockingServers,
    NavigateToPoseServer,
)
from tiago_sim.sim_node.controllers import TrajectoryControllers
from tiago_sim.sim_node.localisation_topics import LocalisationTopics
from tiago_sim.sim_node.named_motions import named_motions
from tiago_sim.sim_node.navigation import Navigation
from tiago_sim.sim_node.play_motion import PlayMotion2Server
from tiago_sim.sim_node.sim_thread import SimThread
from tiago_sim.sim_node.tf_topic import MapToOdomBroadcast, static_transforms

log = logging.getLogger(__name__)


class RobotInterfaces:
    """The controllers, the velocity input and the navigation goal, on the sim node's node."""

    def __init__(
        self,
        node: Node,
        world: World,
        sim_thread: SimThread,
        navigation: Navigation,
        localisation_topics: LocalisationTopics,
        motions: MotionLibrary,
    ) -> None:
        self.controllers = TrajectoryControllers(node, sim_thread)
        self.play_motion = PlayMotion2Server(node, sim_thread, named_motions(motions))
        self.tf = MapToOdomBroadcast(node)
        localisation_topics.correction_listeners.append(self.tf.update)
        static_transforms(node, fixed_frames(build_urdf()))
        self.velocity = BaseVelocityInput(node, sim_thread)
        self.navigation = NavigateToPoseServer(node, navigation, sim_thread)
        self.planner = ComputePathToPoseServer(node, navigation, sim_thread)
        self.docking = DockingServers(node, world, navigation, sim_thread)

    def log_use(self) -> None:
        """How many goals each controller ran (a run's summary, on the way out)."""
        counts = ", ".join(f"{group} {count}" for group, count in self.controllers.goals.items() if count)
        log.info("the robot's own interfaces: controller goals: %s", counts or "none")
        log.info("the robot's own interfaces: named motions played: %d", self.play_motion.played)
