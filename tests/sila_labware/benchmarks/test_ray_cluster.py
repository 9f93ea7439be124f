"""`bench --cluster`: a campaign's trials as Ray tasks on a real two-node Ray cluster on this machine.

The cluster is Ray's own (a head and a second node, each with its own raylet, one CPU each); the
trials are real (robot side, bridge, SiLA servers, client), run by the CLI as a user runs it; their
SiLA servers and DDS stay on 127.0.0.1. Every Ray process is stopped at the end of each test,
whatever happened.

What "the same trial" means here: the same seed draws the same disturbances, so a trial on any node
ends as its `--jobs` run does (outcome and cause). Its robot time and plate error are not repeatable
to a simulation step or a millimetre: the robot side's clock also runs, at 1x wall time, while the
robot software computes (campaign.py), so two `--jobs` runs of one seed already differ (measured:
up to 1.7 s of about 70 s simulated, 1.6 mm of placement error; on a loaded machine one trial's
robot time once differed by 17 %). So the test compares what the seed decides (outcome, cause, the
steps run) and the placement error within 3 mm, not robot time to the step length the issue asked
for (docs/benchmarks/index.md).
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from sila_labware.benchmarks.campaign import PORTS_PER_WORKER
from sila_labware.benchmarks.cluster_overhead import descendants
from sila_labware.benchmarks.ray_campaign import SILA2_ENVIRONMENT
from tests.helpers.sila_stack import DEFAULT_WORLD, free_port_base
from tests.sila_labware.benchmarks.test_bench import CLI, run_bench

SEED = 4247
# Plate nests mounted off their place by 6 mm (one standard deviation; the default is 1): the first
# seed's plate misses its destination nest by about 11 mm (positioning), the second's lands within
# 0.3 mm, far from either side of the nest's tolerance (measured over two `--jobs` runs of 12 seeds;
# at 4 mm the pair 4242/4243 had a borderline second trial that flipped either way).
FAULTS = ("--nest-error-mm", "6")
PLATE_ERROR_SPREAD_MM = 3.0
# On the machine's own address, not 127.0.0.1: a Ray driver in another process turns a loopback
# address into the machine's before it connects (ray._private.services.resolve_ip_for_localhost).
NODE = {"num_cpus": 1, "object_store_memory": 80 * 1024 * 1024}


@contextmanager
def two_node_cluster(monkeypatch: pytest.MonkeyPatch, keep_logs_in: Path) -> Iterator[tuple[Any, Any]]:
    """A head and a second node, each with its own raylet; all of their processes stopped on exit.
    Ray's files (sockets, logs, and the "current cluster" note `ray.init("auto")` reads) stay in a
    folder of the test's own: another run's `auto` never finds this cluster. Its logs are copied to
    `keep_logs_in` if the test fails inside."""
    from ray.cluster_utils import Cluster

    temp_dir = tempfile.mkdtemp(prefix="ray-", dir="/tmp")  # Ray's socket paths must stay short
    monkeypatch.setenv("RAY_TMPDIR", temp_dir)
    for name in SILA2_ENVIRONMENT:  # as `ray start` in a shell has it: sila2 never imported there
        monkeypatch.delenv(name, raising=False)
    Path(temp_dir, "ray").mkdir()
    cluster = Cluster()
    try:
        cluster.add_node(**NODE, include_dashboard=False)
        second = cluster.add_node(**NODE)
        cluster.wait_for_nodes()
        yield cluster, second
    except BaseException:
        # Ray's own logs go with its folder: keep them where pytest keeps the failed test's files
        # (a cluster campaign hung once in an idle CI run, and nothing said where)
        logs = Path(temp_dir, "ray", "session_latest", "logs")
        if logs.is_dir():
            shutil.copytree(logs, keep_logs_in / "ray-logs", dirs_exist_ok=True)
        raise
    finally:
        cluster.shutdown()
        shutil.rmtree(temp_dir, ignore_errors=True)


def short_id(node: Any) -> str:
    return node.node_id[:12]


def by_seed(summary: dict[str, Any]) -> dict[int, dict[str, Any]]:
    return {outcome["seed"]: outcome for outcome in summary["outcomes"]}


def test_trials_on_two_nodes_end_as_their_seeds_jobs_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    campaign = ["--trials", "2", "--seed", str(SEED), *FAULTS, "--json"]
    # each run takes under a minute: a bound of 120 s each keeps both inside pytest's 300 s, so a
    # hang ends with what the bench printed
    on_workers = json.loads(run_bench(*campaign, "--jobs", "2", timeout_s=120.0).stdout)
    report = tmp_path / "report"
    with two_node_cluster(monkeypatch, tmp_path) as (cluster, second):
        address, nodes = cluster.address, {short_id(cluster.head_node), short_id(second)}
        done = run_bench(*campaign, "--cluster", address, "--report", str(report), timeout_s=120.0)
    assert done.stdout.strip(), done.stderr[-3000:]
    summary = json.loads(done.stdout)
    assert summary["cluster"] == address and summary["trials"] == 2
    assert {outcome["node"].rpartition("/")[2] for outcome in summary["outcomes"]} == nodes  # both ran some
    assert summary["successes"] == 1, "the faults fail the first seed's trial and not the second's"
    expected = by_seed(on_workers)
    for seed, outcome in by_seed(summary).items():
        alone = expected[seed]
        assert (outcome["success"], outcome["cause"]) == (alone["success"], alone["cause"]), seed
        # the same steps ran (to the same failing one); robot time is not compared (see above)
        assert [step["name"] for step in outcome["steps"]] == [step["name"] for step in alone["steps"]], seed
        if outcome["success"]:
            assert outcome["plate_position_error_mm"] == pytest.approx(
                alone["plate_position_error_mm"], abs=PLATE_ERROR_SPREAD_MM
            ), seed
        assert outcome["world"] == alone["world"] and not outcome["lost_runs"]
    # the same report as a --jobs run's: a line per trial as it ended, the charts, the first run's pictures
    logged = [json.loads(line) for line in (report / "trials.jsonl").read_text().splitlines()]
    assert sorted(line["seed"] for line in logged) == [SEED, SEED + 1]
    for name in ("summary.json", "success_by_cause.png", "run_strip.png"):
        assert (report / name).stat().st_size > 100, name
    for failed in summary["failed_trials"]:
        assert f"bench --replay {failed['seed']}" in done.stderr


def _robot_sides_under(root: int) -> list[int]:
    pids = []
    for pid in descendants(root):
        try:
            if Path(f"/proc/{pid}/comm").read_text().strip() in ("tiago_twin", "sim_node"):  # forked or not
                pids.append(pid)
        except OSError:
            continue
    return pids


def test_a_node_lost_mid_campaign_has_its_trial_run_again_on_the_head_marked_as_infrastructure(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    report = tmp_path / "report"
    stack = ["--insecure", "--no-discovery", "--port-base", str(free_port_base(2 * PORTS_PER_WORKER))]
    campaign = ["--trials", "2", "--seed", str(SEED), "--json", "--report", str(report)]
    with two_node_cluster(monkeypatch, tmp_path) as (cluster, second):
        raylet = second.all_processes["raylet"][0].process.pid
        command = [*CLI, "bench", *stack, *campaign, "--cluster", cluster.address]
        with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as bench:
            try:
                deadline = time.monotonic() + 120
                while not (orphans := _robot_sides_under(raylet)):  # the second node's trial is running
                    assert bench.poll() is None and time.monotonic() < deadline, "no trial on the second node"
                    time.sleep(0.5)
                cluster.remove_node(second, allow_graceful=False)
                stdout, stderr = bench.communicate(timeout=240)
            finally:
                if bench.poll() is None:
                    bench.send_signal(signal.SIGINT)
                    bench.communicate(timeout=30)
        head = short_id(cluster.head_node)
    assert stdout.strip(), stderr[-3000:]
    summary = json.loads(stdout)
    assert summary["trials"] == 2 and bench.returncode in (0, 1), stderr[-3000:]
    rerun = [outcome for outcome in summary["outcomes"] if outcome["lost_runs"]]
    assert len(rerun) == 1, stderr[-3000:]
    assert rerun[0]["node"].endswith(head)  # ran again, on the node that was left
    assert rerun[0]["lost_runs"][0].startswith(("node lost", "worker lost"))
    assert rerun[0]["error"] == "" or "lost" not in rerun[0]["error"]  # a robot's outcome, not the loss
    assert summary["rerun_trials"] == [{"seed": rerun[0]["seed"], "lost_runs": rerun[0]["lost_runs"]}]
    assert json.loads((report / "summary.json").read_text())["rerun_trials"] == summary["rerun_trials"]
    # the lost trial's robot side stops itself once its starter is gone
    assert not _still_running_after(orphans, 15.0), "the lost node's robot side kept running"


def _still_running_after(pids: list[int], timeout_s: float) -> list[int]:
    """The processes still running after `timeout_s`, killed then: never left to the next test."""
    deadline = time.monotonic() + timeout_s
    while any(map(_running, pids)) and time.monotonic() < deadline:
        time.sleep(0.5)
    left = [pid for pid in pids if _running(pid)]
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    return left


def _running(pid: int) -> bool:
    """Alive and not a zombie (an orphan's zombie waits for whoever adopted it)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


def bench_quickly(*arguments: str, environment: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*CLI, "bench", "--insecure", "--no-discovery", "--trials", "1", "--json", *arguments],
        capture_output=True,
        text=True,
        timeout=120,
        env=environment,
    )


def test_cluster_excludes_jobs_and_domain_id() -> None:
    for flag in (["--jobs", "2"], ["--domain-id", "7"]):
        done = bench_quickly("--cluster", "local", *flag)
        assert done.returncode == 2 and f"--cluster and {flag[0]} exclude each other" in done.stderr


def test_a_cluster_that_cannot_be_reached_ends_the_campaign_with_a_clear_error() -> None:
    with socket.socket() as closed:  # a port nobody listens on
        closed.bind(("127.0.0.1", 0))
        port = closed.getsockname()[1]
    done = bench_quickly("--cluster", f"127.0.0.1:{port}")
    assert done.returncode == 1 and f"no Ray cluster answers at 127.0.0.1:{port}" in done.stderr
    assert json.loads(done.stdout)["error_kind"] == "start_failed"
    done = bench_quickly("--cluster", "head-without-port")
    assert done.returncode == 1 and "expected HOST:PORT" in done.stderr


def test_a_cluster_with_no_cpu_ends_the_campaign_with_a_clear_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A head that takes no tasks (`num-cpus 0`, as on Kubernetes) and no worker node."""
    from ray.cluster_utils import Cluster

    from sila_labware.benchmarks import ray_campaign
    from sila_labware.benchmarks.campaign import CampaignOptions
    from sila_labware.benchmarks.levels import default_level_values
    from sila_labware.deployment.stack import DeploymentOptions

    monkeypatch.setattr(ray_campaign, "NO_CPU_GRACE_S", 2.0)  # an autoscaler's minute, shortened
    temp_dir = tempfile.mkdtemp(prefix="ray-", dir="/tmp")
    monkeypatch.setenv("RAY_TMPDIR", temp_dir)
    Path(temp_dir, "ray").mkdir()
    cluster = Cluster()
    try:
        cluster.add_node(num_cpus=0, object_store_memory=NODE["object_store_memory"], include_dashboard=False)
        options = CampaignOptions(DeploymentOptions(world=DEFAULT_WORLD), SEED, 1, default_level_values())
        with pytest.raises(ray_campaign.ClusterError, match="no CPU for 2 s: no node can run a trial"):
            ray_campaign.run_cluster_campaign(options, cluster.address, progress_stream=None)
    finally:
        cluster.shutdown()
        shutil.rmtree(temp_dir, ignore_errors=True)


def test_a_trial_on_a_node_gets_the_drivers_world_and_layout_as_files_of_its_own(tmp_path: Path) -> None:
    """What a task carries to a node that has none of the driver's files, and what it does there."""
    from sila_labware.benchmarks.campaign import CampaignOptions, layout_path
    from sila_labware.benchmarks.levels import default_level_values
    from sila_labware.benchmarks.ray_trial import TrialFiles, options_on_node
    from sila_labware.deployment.stack import DeploymentOptions

    driver, node = tmp_path / "driver", tmp_path / "node"
    driver.mkdir(), node.mkdir()
    layout_path(driver, SEED).write_text("name: random layout\n")
    stack = DeploymentOptions(world=DEFAULT_WORLD, port_base=free_port_base(PORTS_PER_WORKER), domain_id=7)
    options = CampaignOptions(stack, SEED, 1, default_level_values(), layouts_dir=driver, jobs=2)
    files = TrialFiles.of(options, SEED)
    local = options_on_node(options, SEED, files, node)
    assert local.stack.world.read_text() == DEFAULT_WORLD.read_text() and local.stack.world.parent == node
    assert layout_path(local.layouts_dir, SEED).read_text() == "name: random layout\n"
    assert local.stack.ca_file.parent == node and local.stack.domain_id is None  # reserved on its host
    assert local.stack.port_base >= stack.port_base and (local.jobs, local.record_dir) == (1, None)


def test_sigterm_stops_a_cluster_campaign_its_trials_and_its_local_cluster(tmp_path: Path) -> None:
    """Ray's core worker installs a SIGTERM handler that aborts the process: the bench puts its own
    back, so SIGTERM stops the running trials and the summary says what was done (exit 130)."""
    stack = ["--insecure", "--no-discovery", "--port-base", str(free_port_base(2 * PORTS_PER_WORKER))]
    command = [*CLI, "bench", *stack, "--trials", "3", "--seed", str(SEED), "--json", "--cluster", "local"]
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as bench:
        try:
            deadline = time.monotonic() + 120
            while not (robot_sides := _robot_sides_under(bench.pid)):  # a trial is running
                if bench.poll() is not None or time.monotonic() > deadline:
                    pytest.fail(f"no trial started; the bench printed:\n{bench.communicate()[1][-3000:]}")
                time.sleep(0.5)
            bench.send_signal(signal.SIGTERM)
            stdout, stderr = bench.communicate(timeout=60)
        finally:
            if bench.poll() is None:
                bench.kill()
                bench.communicate(timeout=30)
    assert bench.returncode == 130, stderr[-3000:]
    assert json.loads(stdout)["error_kind"] == "interrupted"
    assert not _still_running_after(robot_sides, 15.0), "the interrupted trial's robot side kept running"
