"""A trial whose robot side does not come up runs once more, counted apart, not as a robot failure.

Why: in a loaded CI run a trial's sequencer hung in rclpy's node creation (DDS) for the whole 180 s
start-up, and the trial failed as "could not start" among the robot's failures. The first start is
made to fail as that one did (fault injection at the deployment's start); the second is a real
deployment, a real transfer.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from lab_description.world import DEFAULT_WORLD
from ros_bridge.errors import BridgeError
from sila_labware.benchmarks import campaign
from sila_labware.benchmarks.campaign import CampaignOptions, format_table, run_trial, summarize
from sila_labware.benchmarks.levels import default_level_values
from sila_labware.deployment.stack import Deployment, DeploymentOptions
from sila_labware.testing.ports import free_port_base

SEED = 4243  # delivers (test_bench.py's second seed)
HUNG = "the robot side did not come up within 180 s: action server /get_labware not available"


def test_a_trial_whose_robot_side_did_not_start_runs_again_and_is_listed_apart(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    starts: list[int] = []

    class FirstStartHangs(Deployment):
        def start(self, *args, **kwargs) -> None:
            starts.append(1)
            if len(starts) == 1:
                raise BridgeError(HUNG)
            super().start(*args, **kwargs)

    monkeypatch.setattr(campaign, "Deployment", FirstStartHangs)
    stack = DeploymentOptions(
        world=DEFAULT_WORLD,
        port_base=free_port_base(10),
        insecure=True,
        discovery=False,
        ca_file=tmp_path / "ca.pem",
    )
    options = CampaignOptions(stack, SEED, 1, default_level_values())
    outcome = run_trial(options, SEED)
    assert len(starts) == 2
    assert outcome.success and outcome.sim_seconds > 0, outcome.error
    assert outcome.lost_runs == [f"could not start: BridgeError: {HUNG}"]
    summary = summarize([outcome], {}, SEED)
    assert summary["successes"] == 1 and summary["rerun_trials"][0]["seed"] == SEED
    assert "did not start (infrastructure, not counted as failures)" in format_table(summary)
