"""The stand-alone servers (the path for a real robot): each attaches to a robot side that is
already running, here the real sim node and sequencer started by the test."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

from sila2.client import SilaClient

from sila_labware.deployment.processes import ProcessGroup, ros_environment
from tests.helpers.sila_stack import DEFAULT_WORLD, free_port_base


def start_server(module: str, port: int, ca_file: Path, *extra: str) -> subprocess.Popen:
    return subprocess.Popen(
        [
            sys.executable,
            "-m",
            module,
            "--port",
            str(port),
            "--ca-file",
            str(ca_file),
            "--no-discovery",
            *extra,
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=ros_environment(int(os.environ["ROS_DOMAIN_ID"])),
    )


def test_robot_and_station_servers_attach_to_a_running_robot_side(tmp_path: Path) -> None:
    robot_side = ProcessGroup(ros_environment(int(os.environ["ROS_DOMAIN_ID"])), tmp_path / "logs")
    servers: list[subprocess.Popen] = []
    try:
        for name, module in (("sim_node", "tiago_twin"), ("sequencer", "tiago_sim.sequencer")):
            robot_side.start_python_module(name, module, ["--world", str(DEFAULT_WORLD)])
        port = free_port_base(2)
        servers.append(start_server("sila_labware.servers.robot_server", port, tmp_path / "robot-ca.pem"))
        servers.append(
            start_server(
                "sila_labware.servers.station_server",
                port + 1,
                tmp_path / "station-ca.pem",
                "--station",
                "station_b",
            )
        )
        for server in servers:
            assert server.stdout is not None
            line = server.stdout.readline()
            assert " at 127.0.0.1:" in line, server.stderr.read() if server.poll() is not None else line

        robot = SilaClient("127.0.0.1", port, root_certs=(tmp_path / "robot-ca.pem").read_bytes())
        assert robot.LabwareTransferManipulatorController.NumberOfInternalPositions.get() == 2
        station = SilaClient("127.0.0.1", port + 1, root_certs=(tmp_path / "station-ca.pem").read_bytes())
        positions = station.LabwareTransferSiteController.AvailableHandoverPositions.get()
        assert [(item.Position, item.SubPosition) for item in positions] == [("station_b", 2)]

        for server in servers:
            server.send_signal(signal.SIGTERM)
        assert [server.wait(timeout=10) for server in servers] == [0, 0]
    finally:
        for server in servers:
            if server.poll() is None:
                server.kill()
                server.wait()
        robot_side.stop()


def test_standalone_server_without_robot_side_names_what_is_missing() -> None:
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "sila_labware.servers.station_server",
            "--ready-timeout",
            "0.5",
            "--station",
            "oven",
        ],
        capture_output=True,
        text=True,
        timeout=60,
        env=ros_environment(int(os.environ["ROS_DOMAIN_ID"])),
    )
    assert done.returncode == 1
    assert "sila_labware.servers.station_server: action server /navigate_to_poi" in done.stderr
    assert "not available after 0.5 s" in done.stderr
