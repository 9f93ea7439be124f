"""The one-transfer benchmark reads the sim node's log: goal spans and marker sightings.

Why: the log lines are written by tiago_skills.action_servers and
tiago_skills.marker_motion; if their format drifts, the benchmark would silently time nothing
or compare a sighting with the wrong ground truth. The lines below are copied in shape from a real
run of the sim node.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from lab_description.world import DEFAULT_WORLD, load_world
from tiago_description import transforms as tf
from tiago_sim.measuring import benchmark

PREFIX = "2026-11-23 17:10:19,711 INFO "


def _write(tmp_path: Path, lines: list[str]) -> Path:
    path = tmp_path / benchmark.ROBOT_LOG
    path.write_text("".join(PREFIX + line + "\n" for line in lines))
    return path


def test_goal_spans_read_start_end_and_time_without_motion(tmp_path: Path) -> None:
    log = _write(
        tmp_path,
        [
            "tiago_skills.action_servers: /undock done: sim 4.133 .. 6.833 s, 0.042 s of it with "
            "no motion running",
            "tiago_skills.marker_motion: marker 3 of station_a at [ 0.8 -0.1  0.84 ] in base, "
            "quaternion [0 0 0 1] "
            "(reprojection 0.09 px)",
            "tiago_skills.action_servers: /marker_motion MARKER_NOT_FOUND: sim 13.5 .. 18.7 s, "
            "0.342 s of it with "
            "no motion running",
        ],
    )
    assert benchmark._goal_spans(log) == [
        ("/undock", 4.133, 6.833, 0.042),
        ("/marker_motion", 13.5, 18.7, 0.342),
    ]


def test_only_sightings_from_where_the_base_stood_are_compared(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    world = load_world(DEFAULT_WORLD)
    station = world.stations[0]
    base = station.aligned_pose()
    truth = tf.invert(base.matrix()) @ station.T_world_marker()
    # 1 mm off along x and turned 0.5 deg about the marker's own z axis
    seen = truth @ tf.from_xyz_rpy((0.0, 0.0, 0.0), (0.0, 0.0, np.radians(0.5)))
    seen[:3, 3] += (0.001, 0.0, 0.0)
    position = " ".join(f"{v:.4f}" for v in seen[:3, 3])
    quaternion = " ".join(f"{v:.5f}" for v in tf.matrix_to_quat(seen[:3, :3]))
    sighting = f"tiago_skills.marker_motion: marker {station.marker_id} of {station.name} at"
    log = _write(
        tmp_path,
        [
            f"{sighting} [ 0.9 -0.1 0.84 ] in base, quaternion [0.5 -0.5 0.5 -0.5] (reprojection 0.09 px)",
            f"tiago_skills.base_alignment: aligning at {station.name}: "
            "working pose at x 0.218 y 0.002 m, "
            "yaw 0.2 deg from here",
            f"{sighting} [ {position} ] in base, quaternion [{quaternion}] (reprojection 0.10 px)",
        ],
    )
    ground_truth = {station.name: SimpleNamespace(x=base.x, y=base.y, theta=base.yaw)}
    benchmark._marker_errors(log, world, ground_truth, np, tf)
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 2
    assert "before the final approach" in lines[0]
    position_mm = float(lines[1].split("position error ")[1].split()[0])
    orientation_deg = float(lines[1].split("orientation error ")[1].split()[0])
    assert position_mm == pytest.approx(1.0, abs=0.1)
    assert orientation_deg == pytest.approx(0.5, abs=0.02)
