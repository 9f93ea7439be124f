"""The repeatability bench: seeded disturbances, a small real campaign, its table and its report.

The campaign runs the real stack (sim node, sequencer, bridge, SiLA servers) through the CLI, as
a user would; a replay of one seed runs it again with the same disturbances (not as the same run:
the robot side's clock also runs while the robot software computes), and says so.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from lab_description.world import load_world
from sila_labware.benchmarks.campaign import PORTS_PER_WORKER
from sila_labware.benchmarks.failure_causes import CAUSES, classify_failure
from sila_labware.benchmarks.levels import LEVEL_FLAGS, levels_json
from sila_labware.deployment.demo import DemoReport
from tests.helpers.sila_stack import free_port_base
from tiago_sim.measuring import disturbances

CLI = [sys.executable, "-m", "sila_labware.cli"]
SEED = 4242


def run_bench(*arguments: str, timeout_s: float = 240.0) -> subprocess.CompletedProcess:
    """`bench` as a user runs it. Past `timeout_s` (inside pytest's 300 s) it is stopped as Ctrl-C
    would, so its robot side is stopped too, and the test fails with what it printed (a run hung
    once in CI, and SIGKILL had lost its output)."""
    stack = ["--insecure", "--no-discovery", "--port-base", str(free_port_base(2 * PORTS_PER_WORKER))]
    command = [*CLI, "bench", *stack, *arguments]
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as bench:
        try:
            stdout, stderr = bench.communicate(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            bench.send_signal(signal.SIGINT)
            stdout, stderr = bench.communicate(timeout=30.0)
            pytest.fail(f"bench did not finish within {timeout_s:.0f} s; it printed:\n{stderr[-4000:]}")
    return subprocess.CompletedProcess(command, bench.returncode, stdout, stderr)


def test_bench_flag_defaults_are_the_sim_default_level() -> None:
    """The CLI documents the levels in mm/deg/%; converted, they are DisturbanceLevels' defaults."""
    sent = json.loads(levels_json({level.field: level.default for level in LEVEL_FLAGS}))
    expected = dataclasses.asdict(disturbances.DisturbanceLevels())
    assert sent.keys() == expected.keys()
    for name, value in expected.items():
        assert math.isclose(sent[name], value, rel_tol=1e-9), name


def test_disturbances_are_seeded_and_move_the_true_world_only() -> None:
    world = load_world()
    levels = disturbances.DisturbanceLevels()
    first, again, other = (disturbances.draw(world, seed, levels) for seed in (7, 7, 8))
    assert first == again and first != other
    true_world = disturbances.true_world(world, first)
    believed = disturbances.believed_world(world, first)
    for nominal, moved in zip(world.stations, true_world.stations, strict=True):
        site_shift = np.linalg.norm(moved.T_world_site(1)[:3, 3] - nominal.T_world_site(1)[:3, 3])
        assert 0.0 < site_shift < 0.1  # moved, by at most a few centimetres (3 sigma clip)
        # a marker mounted off its place does not move the nests: only the station and nest errors do
        without_marker = dataclasses.replace(
            first, marker={name: disturbances.PlanarOffset() for name in first.marker}
        )
        with_marker = dataclasses.replace(first, marker=first.marker)
        a = disturbances.true_world(world, without_marker).station(nominal.name).T_world_site(2)
        b = disturbances.true_world(world, with_marker).station(nominal.name).T_world_site(2)
        np.testing.assert_allclose(a, b, atol=1e-9)
    assert believed.stations == world.stations  # the robot's calibration stays nominal
    station_pois = {station.poi for station in world.stations}
    for name, pose in world.pois.items():
        moved_pose = believed.pois[name]
        assert (moved_pose != pose) == (name in station_pois)
    undisturbed = disturbances.draw(world, 7, levels.scaled(0.0))
    for nominal, same in zip(
        world.stations, disturbances.true_world(world, undisturbed).stations, strict=True
    ):
        np.testing.assert_allclose(same.T_world_site(2), nominal.T_world_site(2), atol=1e-12)


@pytest.mark.parametrize(
    ("error", "cause"),
    [
        ("DefinedExecutionError: GetLabware failed (MARKER_NOT_FOUND): marker not found: 3", "perception"),
        ("GetLabware failed (GRASP_FAILED): fingers closed on nothing", "grasp"),
        ("driving to station_b_work failed (NAVIGATION_FAILED): blocked", "navigation"),
        ("Undock failed (MOTION_FAILED): stalled", "navigation"),
        ("PutLabware failed (IK_FAILED): no solution", "positioning"),
        ("physics check: the plate is not in station_b/1; it is at floor", "positioning"),
        ("physics check: the plate rests in station_b/1 but outside the nest's tolerance", "positioning"),
        ("TimeoutError: Robot.GetLabware: not finished after 900 s", "other"),
        # as the demo writes them since it runs the transfer through LabwareTransferClient
        (
            "LabwareNotPicked: Robot.GetLabware: GetLabware failed (MARKER_NOT_FOUND): marker not found: 3",
            "perception",
        ),
        (
            "InvalidCommandSequence: Robot.PrepareForOutput (step B.PrepareForInput + "
            "Robot.PrepareForOutput): PrepareForOutput could not bring the robot to the handover position, "
            "so nothing is prepared: "
            "driving to station_b_work failed (MOTION_FAILED): stalled; the robot stands where it stopped",
            "navigation",
        ),
        ("LabwareNotPlaced: Robot.PutLabware: PutLabware failed (MOTION_FAILED): arm stalled", "positioning"),
        ("StepTimeout: Robot.PutLabware: not finished after 900 s: Robot.PutLabware", "other"),
        (
            "UndefinedServerError: Robot.PrepareForOutput: driving to station_b_work failed (COLLISION): "
            "the hotel tray (base_footprint) touched obstacle bench_c (13.2 mm deep)",
            "collision",
        ),
        (
            "LabwareNotPlaced: PutLabware failed (COLLISION): arm_right_4_link touched station_b table",
            "collision",
        ),
    ],
)
def test_every_failure_message_gets_a_cause(error: str, cause: str) -> None:
    assert classify_failure(DemoReport(error=error)) == cause
    assert cause in CAUSES


def test_small_campaign_table_is_consistent_replays_and_reports(tmp_path: Path) -> None:
    report_dir = tmp_path / "report"
    done = run_bench("--trials", "2", "--seed", str(SEED), "--json", "--report", str(report_dir))
    assert done.stdout.strip(), done.stderr[-3000:]
    summary = json.loads(done.stdout)
    assert summary["trials"] == 2 and len(summary["outcomes"]) == 2
    assert set(summary["failures"]) == set(CAUSES)
    assert summary["successes"] + sum(summary["failures"].values()) == summary["trials"]
    assert summary["success_rate"] == pytest.approx(summary["successes"] / summary["trials"])
    assert [o["seed"] for o in summary["outcomes"]] == [SEED, SEED + 1]
    for outcome in summary["outcomes"]:
        assert (outcome["cause"] == "") == outcome["success"]
        assert outcome["success"] or outcome["cause"] in CAUSES
        assert outcome["sim_seconds"] > 0 and outcome["wall_seconds"] > 0
    assert {f["seed"] for f in summary["failed_trials"]} == {
        o["seed"] for o in summary["outcomes"] if not o["success"]
    }
    assert summary["sim_seconds_median"] > 0 and summary["realtime_factor"] > 0
    assert summary["pace"] is None and summary["remaining_time"]["judged"] is False, "unpaced: not judged"
    # the default levels include the sensor and calibration errors of the real robot
    for flag in ("depth-noise-mm", "camera-mount-mm", "camera-mount-deg", "joint-offset-deg"):
        assert summary["levels"][flag] > 0, flag
    assert done.returncode == (0 if summary["successes"] == 2 else 1), done.stderr[-2000:]
    for name in ("success_by_cause.png", "time_per_phase.png", "run_strip.png"):
        image = cv2.imread(str(report_dir / name))
        assert image is not None and image.shape[0] > 100 and image.shape[1] > 300, name
        assert image.std() > 10, f"{name} is blank"
    assert (report_dir / "run.gif").stat().st_size > 1000
    kept = {
        int(path.name.removeprefix("trial_")) for path in (report_dir / "failed-trial-logs").glob("trial_*")
    }
    assert kept == {failure["seed"] for failure in summary["failed_trials"]}, (
        "a delivered trial's logs stayed"
    )
    assert sorted((report_dir / "frames").glob("head_*.png")), "no head camera frame was recorded"

    replay = run_bench("--replay", str(SEED + 1), "--json")
    replayed = json.loads(replay.stdout)
    assert replayed["trials"] == 1
    assert "not the same run" in replayed["replay_repeats"]
    assert "not the same run" in replay.stderr
    original = summary["outcomes"][1]
    assert (
        replayed["outcomes"][0]["seed"],
        replayed["outcomes"][0]["success"],
        replayed["outcomes"][0]["cause"],
    ) == (
        original["seed"],
        original["success"],
        original["cause"],
    )


def test_replay_says_it_repeats_the_disturbances_not_the_run() -> None:
    shown = subprocess.run([*CLI, "bench", "--help"], capture_output=True, text=True, timeout=60)
    assert shown.returncode == 0, shown.stderr
    help_text = " ".join(shown.stdout.split())
    assert "--replay SEED run the one trial with SEED again: the same disturbances" in help_text
    assert "not the same run" in help_text


def _robot_side_pids(domain_id: str) -> list[int]:
    """sim_node and sequencer processes of this test run's ROS domain, read from /proc (a forked one
    shows the fork server's command line and environment, with its own name)."""
    pids = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            command = (entry / "cmdline").read_bytes()
            name = (entry / "comm").read_text().strip()
            environment = (entry / "environ").read_bytes().split(b"\0")
        except OSError:
            continue
        robot_side = name in ("sim_node", "sequencer")  # forked from the prewarmed fork server
        robot_side |= b"tiago_twin" in command or b"tiago_sim.sequencer" in command
        if robot_side and f"ROS_DOMAIN_ID={domain_id}".encode() in environment:
            pids.append(int(entry.name))
    return pids


def test_sigterm_stops_the_campaign_its_robot_side_and_summarises_what_was_done(tmp_path: Path) -> None:
    """The robot side runs in sessions of its own (a terminal's Ctrl-C never reaches it): SIGTERM to
    the bench once left sim_node and sequencer running. Now the running trial is abandoned, its
    processes stop, and the trials done so far are summarised with exit code 130."""
    domain_id = os.environ["ROS_DOMAIN_ID"]
    stack = ["--no-discovery", "--port-base", str(free_port_base(4))]  # TLS: the run writes a CA file
    temp_dir = tmp_path / "tmp"
    temp_dir.mkdir()
    bench = subprocess.Popen(
        [*CLI, "bench", *stack, "--trials", "3", "--seed", str(SEED), "--json", "--jobs", "1"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "TMPDIR": str(temp_dir)},
    )
    try:
        assert bench.stderr is not None
        for line in bench.stderr:  # the progress line of the first finished trial
            if line.startswith("[") and " 1/3 " in line:
                break
        else:
            pytest.fail("the bench ended before its first trial was done")
        deadline = time.monotonic() + 60
        while not _robot_side_pids(domain_id):  # the second trial's robot side is up
            assert time.monotonic() < deadline, "the second trial never started its robot side"
            time.sleep(0.2)
        bench.send_signal(signal.SIGTERM)
        stdout, stderr = bench.communicate(timeout=30)
    finally:
        if bench.poll() is None:
            bench.kill()
        leftovers = _robot_side_pids(domain_id)
        for pid in leftovers:  # never leave them to the next test in this ROS domain
            os.kill(pid, signal.SIGKILL)
    assert leftovers == [], "the bench left its robot side running"
    assert bench.returncode == 130, stderr[-2000:]
    summary = json.loads(stdout)
    assert summary["trials"] == 1 and summary["interrupted_after_trials"] == 1
    assert "interrupted: trial seed" in stderr
    assert not list(temp_dir.glob("sila-labware-bench-*")), "the run's CA directory outlived it"


def test_a_failed_trials_robot_side_logs_stay_beside_the_report(tmp_path: Path) -> None:
    """A failure that does not come back on replay can only be read from the run that failed."""
    report_dir = tmp_path / "report"
    # nests mounted 30 mm off their place: the plate misses its destination whatever the seed
    done = run_bench(
        "--trials", "1", "--seed", str(SEED), "--nest-error-mm", "30", "--json", "--report", str(report_dir)
    )
    summary = json.loads(done.stdout)
    assert summary["successes"] == 0, summary["outcomes"]
    logs = report_dir / "failed-trial-logs" / f"trial_{SEED}"
    robot_side = (logs / "sim_node.log").read_text()
    assert "tiago_skills.action_servers" in robot_side and "signal 15: shutting down" in robot_side
    assert str(logs) in done.stderr  # the report names what it kept
