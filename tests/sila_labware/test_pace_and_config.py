"""`--pace` reaches the simulation, and `serve --print-config json` tells tooling how to connect.

Behaviour, not timing: a stack started at pace 5 configures the sim node so, and the robot's clock,
measured as the bridge's `robot_pace` does, runs clearly faster than real time while idle (it
would run at 1x without a pace). The JSON document is checked against a client connected with what it lists.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

from rcl_interfaces.srv import GetParameters
from sila2.client import SilaClient

from ros_bridge.robot_pace import RobotPace
from ros_bridge.services import ServiceCaller
from tests.helpers.sila_stack import free_port_base, start_stack

CLI = [sys.executable, "-m", "sila_labware.cli"]


def test_a_stack_started_at_pace_5_runs_the_sim_node_at_pace_5(tmp_path: Path) -> None:
    deployment = start_stack(tmp_path, pace=5.0)
    try:
        assert deployment.runtime is not None and deployment.link is not None
        caller = ServiceCaller(deployment.runtime, GetParameters, "/tiago_sim/get_parameters")
        caller.wait_for_service(10.0)
        names = ["realtime_factor_cap", "idle_realtime_factor"]
        values = caller.call(GetParameters.Request(names=names), 10.0).values
        assert [value.double_value for value in values] == [5.0, 5.0]
        # The bridge hears /robot_state only when it changes (not while idle): feed the robot's
        # clock stamps to a RobotPace directly, as its listener does during a motion.
        pace = RobotPace()
        for _ in range(8):
            pace.observe(deployment.link.robot_status())
            time.sleep(0.5)
        assert pace.factor > 2.5, pace.factor  # idle at 5x real time, not the unpaced 1x
    finally:
        deployment.stop()


def test_serve_print_config_json_lists_what_a_client_connects_to(tmp_path: Path) -> None:
    port_base = free_port_base(4)
    ca_file = tmp_path / "ca.pem"
    serve = subprocess.Popen(
        [*CLI, "serve", "--print-config", "json", "--port-base", str(port_base), "--ca-file", str(ca_file)]
        + ["--no-discovery"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert serve.stdout is not None
        line = serve.stdout.readline()  # the first line on stdout is the document: no logs before it
        assert line, f"serve ended early: {serve.wait(5)} {serve.stderr.read() if serve.stderr else ''}"
        config = json.loads(line)
        assert config["ca_file"] == str(ca_file.resolve())
        servers = config["servers"]
        assert [server["role"] for server in servers] == ["robot", "station", "station"]
        assert [server["port"] for server in servers] == [port_base, port_base + 1, port_base + 2]
        robot = servers[0]
        assert set(robot) >= {"role", "name", "host", "port", "server_uuid", "features"}
        client = SilaClient(robot["host"], robot["port"], root_certs=Path(config["ca_file"]).read_bytes())
        assert client.SiLAService.ServerUUID.get() == robot["server_uuid"]
        assert client.SiLAService.ServerName.get() == robot["name"]
        assert sorted(client.SiLAService.ImplementedFeatures.get()) == robot["features"]
        assert any(
            feature.endswith("/LabwareTransferManipulatorController/v1") for feature in robot["features"]
        )
        serve.send_signal(signal.SIGINT)
        stdout, _stderr = serve.communicate(timeout=10)
        assert serve.returncode == 0
        assert stdout == ""  # the document was the only output on stdout
    finally:
        if serve.poll() is None:
            serve.kill()
            serve.wait()


def test_the_ros_adapter_refuses_a_pace_its_velocity_commands_cannot_keep() -> None:
    from sila_labware.deployment.pacing import pace_problem

    assert pace_problem(10.0, ros_adapter=True) is None
    assert "at most" in (pace_problem(20.0, ros_adapter=True) or "")
    assert pace_problem(20.0) is None
