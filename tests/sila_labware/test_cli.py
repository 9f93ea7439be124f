"""The `sila-labware` command: usage errors, `serve` and `demo` under signals, `demo --json`, and
what a run leaves in the temp folder (nothing). Through the installed entry point (the console
script a user types), and the Ctrl-C test through `./run demo`."""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import cv2
import numpy as np
import pytest
from sila2.client import SilaClient

from tests.helpers.run_script import RUN, assert_set_up
from tests.helpers.sila_stack import free_port_base

CLI = [str(Path(sys.executable).with_name("sila-labware"))]


def run_cli(
    *arguments: str, timeout_s: float = 30.0, temp_dir: Path | None = None
) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*CLI, *arguments], capture_output=True, text=True, timeout=timeout_s, env=_environment(temp_dir)
    )


def _environment(temp_dir: Path | None) -> dict[str, str]:
    """This run's environment, with its temp folder in `temp_dir` (to see what the CLI leaves)."""
    environment = dict(os.environ)
    if temp_dir is not None:
        temp_dir.mkdir(parents=True, exist_ok=True)
        environment["TMPDIR"] = str(temp_dir)
    return environment


def left_in_temp(temp_dir: Path) -> list[str]:
    """What a run left in its temp folder of its own making (the `sila-labware-*` entries, but the
    ROS domain locks, which are shared by design)."""
    return sorted(
        entry.name
        for entry in temp_dir.iterdir()
        if entry.name.startswith("sila-labware-") and entry.name != "sila-labware-ros-domains"
    )


def test_help_lists_subcommands() -> None:
    done = run_cli("--help")
    assert done.returncode == 0
    assert "serve" in done.stdout and "demo" in done.stdout
    serve_help = run_cli("serve", "--help")
    for option in ("--world", "--host", "--port-base", "--insecure", "--ca-file"):
        assert option in serve_help.stdout
    assert "--json" in run_cli("demo", "--help").stdout


@pytest.mark.parametrize(
    ("arguments", "reason"),
    [
        ((), "the following arguments are required"),
        (("fly",), "invalid choice: 'fly'"),
        (("serve", "--bogus"), "unrecognized arguments: --bogus"),
        (("serve", "--port-base", "many"), "invalid int value: 'many'"),
        (("serve", "--pace", "0"), "--pace 0 is outside 0 < X <= 1000"),
        (("demo", "--pace", "1001"), "--pace 1001 is outside 0 < X <= 1000"),
        (("demo", "--world", "/no/such/world.yaml"), "world file not found: /no/such/world.yaml"),
    ],
)
def test_bad_usage_exits_non_zero_with_one_line(arguments: tuple[str, ...], reason: str) -> None:
    done = run_cli(*arguments)
    assert done.returncode == 2
    assert done.stdout == ""
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sila-labware"), done.stderr
    assert reason in lines[0]


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


@pytest.mark.parametrize("stop_signal", [signal.SIGINT, signal.SIGTERM])
def test_serve_prints_servers_and_stops_everything_quickly(
    tmp_path: Path, stop_signal: signal.Signals
) -> None:
    port_base = free_port_base(4)
    ca_file, inventory = tmp_path / "ca.pem", tmp_path / "inventory.json"
    serve = subprocess.Popen(
        [
            *CLI,
            "serve",
            "--port-base",
            str(port_base),
            "--ca-file",
            str(ca_file),
            "--no-discovery",
            "--inventory",
            str(inventory),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        lines: list[str] = []
        assert serve.stdout is not None
        while not lines or lines[-1] != "serving; Ctrl-C stops":
            line = serve.stdout.readline()
            assert line, f"serve ended early: {serve.wait(5)} {serve.stderr.read() if serve.stderr else ''}"
            lines.append(line.rstrip("\n"))
        output = "\n".join(lines)
        assert f"127.0.0.1:{port_base}" in output and "TIAGo Labware Robot" in output
        assert "Station station_a" in output and "Station station_b" in output
        assert f"CA file for clients: {ca_file.resolve()}" in output
        child_pids = [int(pid) for pid in re.findall(r"robot side: \w+ pid (\d+)", output)]
        assert len(child_pids) == 2

        client = SilaClient("127.0.0.1", port_base, root_certs=ca_file.read_bytes())
        assert client.SiLAService.ServerName.get() == "TIAGo Labware Robot (default lab)"

        started = time.monotonic()
        serve.send_signal(stop_signal)
        assert serve.wait(timeout=10) == 0
        assert time.monotonic() - started < 5.0
        assert not any(_pid_alive(pid) for pid in child_pids)
        # the robot side kept its inventory where it was told to: the plate its sensors saw, by its label
        records = json.loads(inventory.read_text())
        assert [(r["labware_id"], r["location"]) for r in records] == [("plate_001", "station:station_a:1")]
    finally:
        if serve.poll() is None:
            serve.kill()
            serve.wait()


def test_demo_json_reports_the_transfer_and_records_pictures(tmp_path: Path) -> None:
    record_dir = tmp_path / "record"
    done = run_cli(
        "demo",
        "--json",
        "--record",
        str(record_dir),
        "--insecure",
        "--no-discovery",
        "--port-base",
        str(free_port_base(4)),
        "--log-dir",
        str(tmp_path / "logs"),
        timeout_s=600,
        temp_dir=tmp_path / "tmp",
    )
    report = json.loads(done.stdout)
    assert set(report) >= {
        "success",
        "plate_position_error_mm",
        "plate_yaw_error_deg",
        "sim_seconds",
        "wall_seconds",
        "steps",
    }
    assert len(report["steps"]) == 6
    assert all(set(step) == {"name", "sim_seconds", "wall_seconds"} for step in report["steps"])
    # each step's remaining-time estimates, checked at its quarters (the figure is the campaigns')
    assert [check["step"] for check in report["remaining"]] == [step["name"] for step in report["steps"]]
    assert all(len(check["errors"]) == 3 for check in report["remaining"])
    assert report["success"] is True, report
    assert (report["error"], report["error_kind"], report["exit_code"]) == ("", "", 0)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "without encryption" in done.stderr.lower()
    assert_run_pictures(record_dir)
    assert left_in_temp(tmp_path / "tmp") == [], "a successful demo leaves nothing in the temp folder"


def test_demo_json_reports_a_start_up_failure_as_an_object_and_cleans_up(tmp_path: Path) -> None:
    """The robot's port is taken: nothing to transfer, but `--json` still prints one object saying
    so, and the run's CA directory goes."""
    port_base = free_port_base(4)
    with socket.socket() as squatter:
        squatter.bind(("127.0.0.1", port_base))
        squatter.listen()
        done = run_cli(
            "demo",
            "--json",
            "--no-discovery",
            "--port-base",
            str(port_base),
            timeout_s=180,
            temp_dir=tmp_path / "tmp",
        )
    assert done.returncode == 1, done.stderr[-2000:]
    report = json.loads(done.stdout)
    assert report["success"] is False
    assert (report["error_kind"], report["exit_code"]) == ("start_failed", 1)
    assert (
        report["error"].startswith("could not start: ")
        and f"127.0.0.1:{port_base} is already in use" in (report["error"])
    )
    assert f"sila-labware: could not start: 127.0.0.1:{port_base} is already in use" in done.stderr
    assert left_in_temp(tmp_path / "tmp") == [], "a failed demo leaves nothing in the temp folder"


def test_ctrl_c_stops_a_demo_mid_transfer_within_5_s_and_leaves_nothing_behind(tmp_path: Path) -> None:
    """SIGINT once the first step of the transfer is done: the demo ends within 5 s with exit code
    130, says so in its JSON object, and neither its robot side (own sessions, which a terminal's
    Ctrl-C never reaches) nor its temp directory survives it."""
    temp_dir = tmp_path / "tmp"
    assert_set_up()  # `./run demo` then execs `sila-labware demo` at once: the signals reach it
    demo = subprocess.Popen(
        [RUN, "demo", "--json", "--no-discovery", "--port-base", str(free_port_base(4))],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_environment(temp_dir),
    )
    stderr_lines: list[str] = []
    try:
        assert demo.stderr is not None
        for line in demo.stderr:
            stderr_lines.append(line)
            if " done in " in line:  # the first step finished: the transfer is under way
                break
        else:
            pytest.fail(f"the demo ended before its first step: {''.join(stderr_lines)[-2000:]}")
        child_pids = [int(pid) for pid in re.findall(r"robot side: \w+ pid (\d+)", "".join(stderr_lines))]
        assert len(child_pids) == 2 and all(_pid_alive(pid) for pid in child_pids)
        rest: list[str] = []
        reader = threading.Thread(target=lambda: rest.extend(demo.stderr), daemon=True)
        reader.start()
        started = time.monotonic()
        demo.send_signal(signal.SIGINT)
        returncode = demo.wait(timeout=30)
        stopped_after_s = time.monotonic() - started
        reader.join(5.0)
        stdout = demo.stdout.read() if demo.stdout else ""
    finally:
        if demo.poll() is None:
            demo.kill()
            demo.wait()
    assert stopped_after_s < 5.0, f"stopped after {stopped_after_s:.1f} s"
    assert returncode == 130, "".join(rest)[-2000:]
    assert not [pid for pid in child_pids if _pid_alive(pid)], "the robot side outlived the demo"
    report = json.loads(stdout)
    assert report["success"] is False and report["error"].startswith("interrupted")
    assert (report["error_kind"], report["exit_code"]) == ("interrupted", 130)
    assert "Traceback" not in "".join(rest), "".join(rest)[-3000:]
    assert left_in_temp(temp_dir) == [], "an interrupted demo leaves nothing in the temp folder"


def assert_run_pictures(record_dir: Path) -> None:
    """`demo --record DIR`: an image strip, a GIF, and head-camera frames with the marker outlined."""
    strip = cv2.imread(str(record_dir / "run_strip.png"))
    assert strip is not None and strip.shape[0] >= 480 and strip.std() > 10
    assert (record_dir / "run.gif").stat().st_size > 1000
    head_frames = sorted((record_dir / "frames").glob("head_*.png"))
    assert len(head_frames) >= 2  # one sighting at each station

    def outlined(frame: Path) -> bool:
        """The outline drawn around a detected marker is the detector's colour (255, 200, 0) in RGB."""
        rgb = cv2.cvtColor(cv2.imread(str(frame)), cv2.COLOR_BGR2RGB)
        return (np.abs(rgb.astype(int) - (255, 200, 0)).sum(axis=2) < 30).sum() > 100  # 2 px: 700 or more

    # not necessarily the first frame: a look taken while the torso still rose may miss the marker
    # and the search looks again (seen once in CI); a depth image for the place has none either
    assert sum(outlined(frame) for frame in head_frames) >= 2, "a marker sighting at each station"


def test_serve_logs_each_refusal_as_one_warning_line_without_a_traceback(tmp_path: Path) -> None:
    """Refused input is the device doing its job: one WARNING line naming the command and the reason
    (sila2 alone wrote an ERROR traceback for each, twice for an observable command)."""
    port_base = free_port_base(4)
    serve = subprocess.Popen(
        [*CLI, "serve", "--insecure", "--port-base", str(port_base), "--no-discovery"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert serve.stdout is not None
        while (line := serve.stdout.readline()) and line.strip() != "serving; Ctrl-C stops":
            pass
        robot = SilaClient("127.0.0.1", port_base, insecure=True)
        manipulator = robot.LabwareTransferManipulatorController
        refusals = [
            lambda: manipulator.GetLabware(
                HandoverPosition={"Position": "station_a", "SubPosition": 1}, IntermediateActions=[]
            ).get_responses(),
            lambda: manipulator.PrepareForOutput(
                HandoverPosition={"Position": "oven", "SubPosition": 1}, InternalPosition=1
            ).get_responses(),
            lambda: robot.MobileRobotController.DriveToPointOfInterest(
                PointOfInterest="attic"
            ).get_responses(),
        ]
        for refuse in refusals:
            with pytest.raises(Exception):  # noqa: B017 - which SiLA error is the servers' tests' concern
                refuse()
        serve.send_signal(signal.SIGINT)
        assert serve.wait(timeout=10) == 0
        log = serve.stderr.read() if serve.stderr else ""
    finally:
        if serve.poll() is None:
            serve.kill()
            serve.wait()
    assert "Traceback" not in log, log[-3000:]
    refused = [line for line in log.splitlines() if " refused: " in line]
    assert all(" WARNING " in line for line in refused), refused
    assert "NoneType: None" not in log
    for command in ("GetLabware", "PrepareForOutput", "DriveToPointOfInterest"):
        assert sum(command in line for line in refused) == 1, (command, refused)


def test_demo_with_stock_sensors_delivers_on_the_camera_and_finger_checks(tmp_path: Path) -> None:
    """No lab-added sensor (`--stock-sensors`): the SiLA side and the robot side check the hotel by
    the fingers and the nest by the head camera, and the demo names its plate as the world file does."""
    logs = tmp_path / "logs"
    done = run_cli(
        "demo",
        "--json",
        "--stock-sensors",
        "--insecure",
        "--no-discovery",
        "--port-base",
        str(free_port_base(4)),
        "--log-dir",
        str(logs),
        timeout_s=600,
        temp_dir=tmp_path / "tmp",
    )
    report = json.loads(done.stdout)
    assert report["success"] is True, report
    assert report["labware_id"] == "plate_001"
    sequencer = (logs / "sequencer.log").read_text()
    assert "lab-added sensors read: none" in sequencer
    assert sequencer.count("target=inspect") == 2, "the nest is looked into before and after the place"
    assert "/station_states" not in sequencer
