"""What Ray adds to a campaign, and what one trial needs: the same campaign on workers and on Ray.

    python -m sila_labware.benchmarks.cluster_overhead --trials 20 --seed S [--jobs 2] [--two-nodes]
                                                      [--json]

Runs `bench --trials N --seed S --jobs J` and then `bench --trials N --seed S --cluster local` (a
one-node Ray cluster on the same cores), or with `--two-nodes` `bench ... --cluster ADDRESS` on a
cluster of J nodes of one CPU each (a raylet each) that this process starts on this machine and
stops after the campaign. Prints, for each, the CPU seconds of its whole process tree per trial, the
wall time and the tree's peak memory; then Ray's overhead per trial (CPU seconds and as a ratio)
and one trial's memory (the workers' peak over J trials at once).

Why CPU seconds: wall time follows the machine's load (a campaign beside another), CPU much less.
The CPU is that of every process the campaign started, Ray's included, counted two ways:
`getrusage(RUSAGE_CHILDREN)` (`interleaved_cpu.measure`: this process is a child subreaper, so what
Ray's processes leave behind is adopted and counted when it ends), and the CPU of each process as
last seen in /proc every quarter second. The first is complete unless a process reaps a child
without passing its CPU on, as a raylet may do with its workers (it did on a two-node cluster, and
on a local one once in two runs): the comparison is of the samples, which miss a process's last
quarter second (about 2 % of a campaign's CPU). Memory is the proportional set size (PSS: pages shared
between processes, such as a prewarmed robot side's, counted once in all) of the tree, sampled too.
Threads: the main thread runs the campaigns; one thread samples /proc.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from sila_labware.benchmarks.interleaved_cpu import become_subreaper, children_cpu_s, measure, reap_orphans

SAMPLE_PERIOD_S = 0.25


class TreeMemory:
    """The peak PSS of every process below this one, and the CPU each used as last seen (no process
    reaps another's CPU away from this count, unlike RUSAGE_CHILDREN: see CLUSTER_SCRIPT), sampled on
    a thread of its own. A process's CPU after its last sample is missed (a sample period at most)."""

    def __init__(self) -> None:
        self.peak_bytes = 0
        self._cpu_ticks: dict[tuple[int, int], int] = {}  # (pid, start time) -> utime + stime
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._sample, name="tree-memory", daemon=True)

    def __enter__(self) -> TreeMemory:
        self._thread.start()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._stop.set()
        self._thread.join()

    @property
    def sampled_cpu_s(self) -> float:
        return sum(self._cpu_ticks.values()) / os.sysconf("SC_CLK_TCK")

    def _sample(self) -> None:
        while not self._stop.wait(SAMPLE_PERIOD_S):
            pids = descendants(os.getpid())
            self.peak_bytes = max(self.peak_bytes, sum(map(_pss_bytes, pids)))
            for pid in pids:
                try:
                    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
                    self._cpu_ticks[(pid, int(fields[19]))] = int(fields[11]) + int(fields[12])
                except (OSError, IndexError, ValueError):
                    continue


def descendants(root: int) -> set[int]:
    """Every process below `root` (read from /proc: the robot side runs in sessions of its own)."""
    parents: dict[int, int] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            parents[int(stat.parent.name)] = int(stat.read_text().rsplit(")", 1)[1].split()[1])
        except (OSError, IndexError, ValueError):
            continue
    found, frontier = set(), {root}
    while frontier:
        frontier = {pid for pid, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


def _pss_bytes(pid: int) -> int:
    try:
        for line in Path(f"/proc/{pid}/smaps_rollup").read_text().splitlines():
            if line.startswith("Pss:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0


CLUSTER_SCRIPT = """
import sys
from ray.cluster_utils import Cluster
cluster = Cluster()
for index in range(int(sys.argv[1])):
    cluster.add_node(num_cpus=1, **({"include_dashboard": False} if index == 0 else {}))
cluster.wait_for_nodes()
print(cluster.address, flush=True)
sys.stdin.read()  # until the benchmark closes it
for node in [*cluster.worker_nodes, cluster.head_node]:
    cluster.remove_node(node, allow_graceful=False)
"""
"""A cluster of one-CPU nodes in a process of its own (its daemons' CPU reaches RUSAGE_CHILDREN when
it ends), killed at the end rather than stopped. Its workers' CPU still does not: the raylets reap
them (measured: about 0.5 CPU s per trial counted of about 6), so the samples of /proc count."""


def run_on_nodes(nodes: int, trials: int, seed: int) -> dict[str, Any]:
    """The campaign on a cluster of `nodes` one-CPU nodes started here: the CPU of every Ray process
    from the cluster's start to its stop, and of the campaign."""
    temp_dir = tempfile.mkdtemp(prefix="ray-")  # Ray's socket paths must stay short
    Path(temp_dir, "ray").mkdir()
    environment = {**os.environ, "RAY_TMPDIR": temp_dir}  # no other `auto` finds this cluster
    cpu_before = children_cpu_s()
    with subprocess.Popen(
        [sys.executable, "-c", CLUSTER_SCRIPT, str(nodes)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        env=environment,
    ) as cluster:
        assert cluster.stdin is not None and cluster.stdout is not None
        address = cluster.stdout.readline().strip()
        command = [sys.executable, "-m", "sila_labware.cli", "bench", "--trials", str(trials)]
        command += ["--seed", str(seed), "--cluster", address, "--json"]
        started = time.monotonic()
        with TreeMemory() as memory:  # this process is the root: the cluster's processes count too
            done = subprocess.run(command, capture_output=True, text=True, env=environment, check=False)
        wall_s = time.monotonic() - started
        cluster.stdin.close()
    reap_orphans()
    shutil.rmtree(temp_dir, ignore_errors=True)
    text = f"sila-labware bench --trials {trials} --seed {seed} --cluster ADDRESS ({nodes} nodes)"
    return _figures(text, done.stdout, trials, children_cpu_s() - cpu_before, wall_s, memory)


def run_one(flags: list[str], trials: int, seed: int) -> dict[str, Any]:
    """One campaign as `bench` runs it: CPU s, wall s, peak memory and what it delivered."""
    command = [sys.executable, "-m", "sila_labware.cli", "bench", "--trials", str(trials)]
    command += ["--seed", str(seed)]
    with TreeMemory() as memory:
        done, cpu_s, wall_s = measure([*command, *flags, "--json"], Path.cwd(), dict(os.environ))
    text = " ".join(["sila-labware", *command[3:], *flags])  # as a user would type it
    return _figures(text, done.stdout, trials, cpu_s, wall_s, memory)


def _figures(
    command: str, stdout: str, trials: int, cpu_s: float, wall_s: float, memory: TreeMemory
) -> dict[str, Any]:
    summary = json.loads(stdout) if stdout.strip() else {}
    return {
        "command": command,
        "trials": summary.get("trials", 0),
        "delivered": summary.get("successes", 0),
        "cpu_seconds": cpu_s,
        "cpu_seconds_per_trial": cpu_s / trials,
        "wall_seconds": wall_s,
        "peak_memory_mb": memory.peak_bytes / 2**20,
        "sampled_cpu_seconds_per_trial": memory.sampled_cpu_s / trials,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--jobs", type=int, default=2, help="workers, and the local cluster's CPUs")
    parser.add_argument("--two-nodes", action="store_true", help="a cluster of --jobs nodes, not one")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    become_subreaper()
    workers = run_one(["--jobs", str(args.jobs)], args.trials, args.seed)
    if args.two_nodes:
        cluster = run_on_nodes(args.jobs, args.trials, args.seed)
    else:
        cluster = run_one(["--cluster", "local"], args.trials, args.seed)
    # rusage may miss Ray's workers (a raylet reaps them; CLUSTER_SCRIPT): the samples miss none
    key = "sampled_cpu_seconds_per_trial"
    overhead = cluster[key] - workers[key]
    figures = {
        "workers": workers,
        "cluster": cluster,
        "compared": key,
        "ray_cpu_seconds_per_trial": overhead,
        "ray_cpu_ratio": cluster[key] / workers[key],
        "memory_per_trial_mb": workers["peak_memory_mb"] / args.jobs,
    }
    if args.json:
        sys.stdout.write(json.dumps(figures, indent=1) + "\n")
    else:
        for run in (workers, cluster):
            sys.stdout.write(
                f"{run['command']}: {run['delivered']}/{run['trials']} delivered, "
                f"{run[key]:.2f} CPU s per trial, {run['wall_seconds']:.0f} s wall, "
                f"peak {run['peak_memory_mb']:.0f} MB\n"
            )
        sys.stdout.write(
            f"Ray's overhead: {overhead:+.2f} CPU s per trial (x{figures['ray_cpu_ratio']:.3f}); "
            f"memory per trial: {figures['memory_per_trial_mb']:.0f} MB\n"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
