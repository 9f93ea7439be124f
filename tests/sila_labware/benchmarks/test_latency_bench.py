"""The latency benchmark runs end to end with a tiny N and prints a well-formed report.

No timing assertions: the figures depend on the machine. What must hold is the shape: every path
measured the number of calls asked for, percentiles are ordered, and the serve timing found every
server it started.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

from sila_labware.benchmarks import latency as latency_bench
from tests.helpers.sila_stack import free_port_base

CALLS, FEEDBACKS = 3, 4


def test_latency_bench_json_report_is_well_formed() -> None:
    completed = subprocess.run(
        [
            sys.executable,
            "-m",
            "sila_labware.benchmarks.latency",
            "--calls",
            str(CALLS),
            "--feedbacks",
            str(FEEDBACKS),
            "--port-base",
            str(free_port_base(4)),
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=240,
        check=False,
    )
    assert completed.returncode == 0, completed.stderr[-3000:]
    report = json.loads(completed.stdout.strip().splitlines()[-1])
    assert (report["calls"], report["feedbacks_per_call"]) == (CALLS, FEEDBACKS)
    for path in ("sila_goal_accept", "rclpy_goal_accept"):
        assert report[path]["samples"] == CALLS, report[path]
    for path in ("sila_feedback", "rclpy_feedback"):
        # Feedback sent before the SiLA client listened is left out, never more than all of it.
        assert 1 <= report[path]["samples"] <= CALLS * FEEDBACKS, report[path]
    for path in ("sila_goal_accept", "rclpy_goal_accept", "sila_feedback", "rclpy_feedback"):
        figures = report[path]
        assert all(math.isfinite(figures[key]) for key in ("p50_ms", "p99_ms", "max_ms")), figures
        assert 0.0 < figures["p50_ms"] <= figures["p99_ms"] <= figures["max_ms"], figures
    assert report["serve_servers"] >= 3  # the robot and the default world's stations
    assert 0.0 < report["serve_printed_s"] and 0.0 < report["serve_discoverable_s"]


def test_latency_bench_refuses_zero_calls(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exited:
        latency_bench.main(["--calls", "0"])
    assert exited.value.code == 2 and "at least 1" in capsys.readouterr().err


def test_percentiles_interpolate_between_ranks() -> None:
    figures = latency_bench.percentiles([0.001 * value for value in range(1, 102)])
    assert (figures.samples, figures.p50_ms, figures.p99_ms, figures.max_ms) == (101, 51.0, 100.0, 101.0)
    assert math.isnan(latency_bench.percentiles([]).p50_ms)
