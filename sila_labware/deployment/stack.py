"""Everything `sila-labware serve` runs: robot-side ROS nodes, the ROS bridge, the SiLA servers.

Order of start: the robot side as child processes (simulation node, task sequencer), the bridge's
ROS runtime in this process, a wait until every ROS server answers, then one SiLA server for the
robot and one per station the robot side describes. `stop()` undoes it in reverse, quickly.

Restarts: the supervisor (supervisor.py) restarts the robot side, and puts the bridge's link on a
new ROS runtime when the ROS thread died. Both go through this class, under one lock, and are
refused once `stop()` has begun, so that nothing is started behind a stop.

Threads: `start`/`stop` run on the caller's thread; restarts on the supervisor's thread; the
bridge adds one ROS thread; each SiLA server has its own gRPC thread pool.
"""

from __future__ import annotations

import logging
import os
import shutil
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from sila2.server import SilaServer

from labware_model.workcell import WorkcellDescription
from ros_bridge.domain import reserve_domain_id
from ros_bridge.errors import BridgeError
from ros_bridge.robot_link import RobotLink
from ros_bridge.runtime import RosRuntime
from ros_bridge.shared_memory import remove_dead_segments
from ros_bridge.simulation_link import SimulationLink
from sila_labware.deployment.lab_name import lab_name_of, robot_server_name, station_server_name
from sila_labware.deployment.pacing import sim_pace_arguments
from sila_labware.deployment.processes import ProcessGroup, interrupts_held, ros_environment
from sila_labware.deployment.supervisor import RobotSideSupervisor
from sila_labware.device.robot_controller import RobotController
from sila_labware.device.simulated_lab import SimulatedLab
from sila_labware.device.station_controller import StationController
from sila_labware.servers.robot_server.server import Server as RobotServer
from sila_labware.servers.serving import start_sila_server, stop_sila_server
from sila_labware.servers.station_server.server import Server as StationServer
from sila_labware.servers.tls import CertificateAuthority

logger = logging.getLogger(__name__)

ROBOT_SIDE_MODULES = (("sim_node", "tiago_twin"), ("sequencer", "tiago_sim.sequencer"))
CHILD_STOP_S = 2.0
"""How long a robot-side child has after SIGTERM before `Deployment.stop` kills it."""


@dataclass
class DeploymentOptions:
    world: Path
    host: str = "127.0.0.1"
    port_base: int = 50052
    insecure: bool = False
    ca_file: Path = Path("sila-labware-ca.pem")
    discovery: bool = True
    domain_id: int | None = None
    ready_timeout_s: float = 180.0
    log_dir: Path | None = None
    extra_sim_arguments: list[str] = field(default_factory=list)
    restart_robot_side: bool = True
    """Restart the robot side when a child ends (see sila_labware.deployment.supervisor)."""
    lab_name: str = ""
    """Carried by every server name (see lab_name.py); empty: the world file's."""
    pace: float | None = None
    """Times real time the simulation runs at (see pacing.py); None: as fast as it can."""
    inventory_file: Path | None = None
    """Where the robot side keeps its labware inventory, so that the names a scheduler gave its
    plates outlive a restart of the robot side; None: a file in a directory of the deployment's own."""
    label_checks: bool = False
    """Refuse a transfer whose plate's label reads other than the scheduler's id (the sequencer's
    `label_checks`); off: such a plate is transferred and the difference noted."""
    prewarmed_robot_side: bool = False
    """Fork the robot side from a process that imported it once (prewarmed.py): for runs that
    start many deployments one after the other, such as a campaign's trials."""


@dataclass(frozen=True)
class ServedServer:
    """One running SiLA server, as clients reach it."""

    name: str
    role: str  # "robot" or "station"
    station: str  # station name for station servers, empty for the robot
    host: str
    port: int
    server: SilaServer


def choose_domain_id(requested: int | None) -> int:
    """The requested id, else ROS_DOMAIN_ID from the environment, else one reserved for this process."""
    if requested is not None:
        return requested
    if os.environ.get("ROS_DOMAIN_ID", "").isdigit():
        return int(os.environ["ROS_DOMAIN_ID"])
    return reserve_domain_id()


def start_robot_side(
    children: ProcessGroup,
    world: Path,
    extra_sim_arguments: Sequence[str] = (),
    pace: float | None = None,
    sequencer_arguments: Sequence[str] = (),
) -> None:
    """Start the robot side's ROS nodes (simulation node, sequencer) as children."""
    for name, module in ROBOT_SIDE_MODULES:
        arguments = ["--world", str(world)]
        if name == "sim_node":
            arguments += [*sim_pace_arguments(pace), *extra_sim_arguments]
        else:
            arguments += sequencer_arguments
        children.start_python_module(name, module, arguments)


def join_ros_domain(domain_id: int) -> None:
    """Put this process's own ROS participants (the bridge) into the deployment's domain."""
    os.environ.update(
        {
            key: value
            for key, value in ros_environment(domain_id).items()
            if key.startswith(("ROS_", "RMW_", "FASTRTPS_"))
        }
    )


class Deployment:
    """Start and stop the whole stack; reach its parts (link, robot, servers) while it runs."""

    def __init__(self, options: DeploymentOptions) -> None:
        self.options = options
        self.domain_id = choose_domain_id(options.domain_id)
        self.children = ProcessGroup(
            ros_environment(self.domain_id), options.log_dir, prewarmed=options.prewarmed_robot_side
        )
        self.runtime: RosRuntime | None = None
        self.link: RobotLink | None = None
        self.workcell: WorkcellDescription | None = None
        self.robot: RobotController | None = None
        self.simulated_lab: SimulatedLab | None = None
        self.servers: list[ServedServer] = []
        self.ca_file: Path | None = None
        self.supervisor: RobotSideSupervisor | None = None
        self._lifecycle_lock = threading.Lock()  # restarts (supervisor) vs. stop (caller)
        self._inventory_file: Path | None = None
        self._stopping = False

    def start(self, should_stop: Callable[[], bool] = lambda: False) -> None:
        """Bring everything up; on any failure, stop what was started and re-raise."""
        # what killed ROS processes of earlier runs left in /dev/shm goes first (it is never reused)
        remove_dead_segments()
        try:
            self._start_robot_side()
            self._start_bridge(should_stop)
            self._start_servers()
            if self.options.restart_robot_side:
                assert self.link is not None and self.robot is not None
                self.supervisor = RobotSideSupervisor(
                    self.children,
                    self._start_robot_side,
                    self.link,
                    self.robot,
                    restart_bridge=self._restart_bridge,
                ).start()
        except BaseException:
            self.stop()
            raise

    def _start_robot_side(self) -> None:
        with self._lifecycle_lock:
            self._refuse_if_stopping()
            start_robot_side(
                self.children,
                self.options.world,
                self.options.extra_sim_arguments,
                self.options.pace,
                self._sequencer_arguments(),
            )

    def _sequencer_arguments(self) -> list[str]:
        """The inventory's file (the same for every restart of this deployment), label checks."""
        if self._inventory_file is None:
            self._inventory_file = self.options.inventory_file or (
                Path(tempfile.mkdtemp(prefix="sila-labware-inventory-")) / "inventory.json"
            )
        arguments = ["--inventory", str(self._inventory_file)]
        return arguments + (["--label-checks"] if self.options.label_checks else [])

    def _new_runtime(self) -> RosRuntime:
        return RosRuntime("sila_labware_bridge", domain_id=self.domain_id).start()

    def _restart_bridge(self) -> None:
        """For the supervisor, after the ROS thread died: a new runtime under the same link."""
        with self._lifecycle_lock:
            self._refuse_if_stopping()
            assert self.link is not None
            if self.runtime is not None:
                self.runtime.stop(timeout_s=1.0)  # ended already: returns at once
            self.runtime = self._new_runtime()
            self.link.attach(self.runtime)

    def _refuse_if_stopping(self) -> None:
        if self._stopping:
            raise BridgeError("the deployment is stopping: nothing more is started")

    def _start_bridge(self, should_stop: Callable[[], bool]) -> None:
        join_ros_domain(self.domain_id)
        with interrupts_held():  # a ROS thread started must be registered, so that stop() ends it
            self.runtime = self._new_runtime()
        self.link = RobotLink(self.runtime)
        deadline = time.monotonic() + self.options.ready_timeout_s
        while True:
            self.children.check_running()
            if should_stop():
                raise KeyboardInterrupt
            try:
                self.link.wait_until_ready(timeout_s=1.0)
                break
            except BridgeError as error:
                if time.monotonic() > deadline:
                    stacks = self.children.stacks()
                    logger.warning("the robot side is not up; its processes' stacks:\n%s", stacks)
                    raise BridgeError(
                        f"the robot side did not come up within {self.options.ready_timeout_s:.0f} s: {error}"
                    ) from error
        self.workcell = self.link.describe_workcell()
        if not self.workcell.stations:
            raise BridgeError("the robot side describes no stations")
        self.robot = RobotController(self.link, self.workcell)

    def _start_servers(self) -> None:
        assert self.robot is not None and self.workcell is not None and self.link is not None
        lab = self.options.lab_name or lab_name_of(self.options.world)
        stations = [StationController(self.link, station) for station in self.workcell.stations]
        # the robot side this deployment starts is always the simulation: offer its controls
        self.simulated_lab = SimulatedLab(SimulationLink(self.link), self.robot, stations, self.options.pace)
        planned: list[tuple[SilaServer, str, str]] = [
            (
                RobotServer(self.robot, name=robot_server_name(lab), simulated_lab=self.simulated_lab),
                "robot",
                "",
            )
        ]
        for controller in stations:
            server = StationServer(controller, name=station_server_name(lab, controller.station.name))
            planned.append((server, "station", controller.station.name))
        authority = None if self.options.insecure else CertificateAuthority()
        for offset, (server, role, station_name) in enumerate(planned):
            port = self.options.port_base + offset
            with interrupts_held():  # a server started must be registered, so that stop() ends it
                start_sila_server(
                    server, self.options.host, port, authority=authority, discovery=self.options.discovery
                )
                self.servers.append(
                    ServedServer(server.server_name, role, station_name, self.options.host, port, server)
                )
        if authority is not None:
            self.ca_file = authority.write_certificate(self.options.ca_file)

    def check_healthy(self) -> None:
        """Raise if the robot side or the bridge is down for good (the supervisor gave up, or
        there is none and a child or the ROS thread ended)."""
        if self.supervisor is not None:
            if self.supervisor.failure:
                raise RuntimeError(self.supervisor.failure)
            return
        self.children.check_running()
        if self.runtime is not None and self.runtime.failure:
            raise RuntimeError(f"the bridge's ROS thread ended ({self.runtime.failure})")

    def robot_server(self) -> ServedServer:
        return next(served for served in self.servers if served.role == "robot")

    def station_server(self, station: str) -> ServedServer:
        return next(served for served in self.servers if served.station == station)

    def stop(self) -> None:
        """Refuse further restarts, then stop the bridge, the servers (in parallel) and the
        children. Safe to call twice. The bridge goes first: its open goals end at once with
        GoalAbandoned, so a command still running ends with its defined error and the server need
        not wait for it. Typically under 1 s; at worst about 5 s (1 s for a restart under way to
        notice, 1 s for the ROS thread, 2 s for the servers; the children got SIGTERM before all
        that and get SIGKILL CHILD_STOP_S after it). Ctrl-C is held meanwhile
        (`interrupts_held`): a stop is never cut short, so that no child is left running."""
        with interrupts_held():
            with self._lifecycle_lock:
                self._stopping = True
            if self.supervisor is not None:
                self.supervisor.stop(timeout_s=1.0)
                self.supervisor = None
            self.children.terminate()  # they stop while the rest does
            terminated_at = time.monotonic()
            if self.runtime is not None:
                self.runtime.stop(timeout_s=1.0)
                self.runtime = None
            stoppers = [
                threading.Thread(target=_stop_server, args=(served.server,), daemon=True)
                for served in self.servers
            ]
            for stopper in stoppers:
                stopper.start()
            for stopper in stoppers:
                stopper.join(2.0)
            self.servers.clear()
            self.children.stop(timeout_s=max(0.0, terminated_at + CHILD_STOP_S - time.monotonic()))
            if self._inventory_file is not None and self.options.inventory_file is None:
                shutil.rmtree(self._inventory_file.parent, ignore_errors=True)  # our own directory


def _stop_server(server: SilaServer) -> None:
    try:
        stop_sila_server(server, grace_period=0.2)
    except Exception:  # noqa: BLE001 - stopping anyway; the reason goes to the log
        logger.warning("stopping SiLA server %s raised", server.server_name, exc_info=True)
