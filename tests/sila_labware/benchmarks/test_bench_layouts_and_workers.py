"""`bench --random-layouts`, `--random-obstacles`, `--save-layout` and `--jobs`: a lab per trial
seed, the failed trials' world files beside the report, workers with ports and ROS domains of their
own, outcomes in seed order. The campaign runs the real stack on two workers (two short trials: CI
has 2 cores)."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import yaml

from lab_description.world import load_world
from sila_labware.benchmarks.campaign import CampaignOptions, TrialOutcome, replay_flags, trial_stack
from sila_labware.benchmarks.levels import default_level_values
from sila_labware.benchmarks.random_layouts import keep_failed_layouts
from sila_labware.deployment.stack import DeploymentOptions
from tests.sila_labware.benchmarks.test_bench import CLI, run_bench
from tiago_sim.layouts.layout_file import furnished_yaml, layout_yaml

SEED = 5161
QUICK_DRAWN_SEED = 5157
"""A layout drawn in well under a second (some seeds take ten: stations refused and drawn again)."""
DEFAULT_WORLD = Path(__file__).resolve().parents[3] / "lab_description" / "worlds" / "default.yaml"


def test_each_worker_gets_its_own_ports_domain_and_ca_file_and_each_trial_its_layout(tmp_path: Path) -> None:
    stack = DeploymentOptions(
        world=Path("lab.yaml"), port_base=57000, domain_id=40, ca_file=tmp_path / "ca.pem"
    )
    options = CampaignOptions(stack, SEED, 4, default_level_values(), jobs=2, layouts_dir=tmp_path)
    first, second = trial_stack(options, SEED, worker=0), trial_stack(options, SEED + 1, worker=1)
    assert (first.port_base, first.domain_id, first.world) == (57000, 40, tmp_path / f"layout_{SEED}.yaml")
    assert (second.port_base, second.domain_id) == (57010, 41)
    assert (first.ca_file, second.ca_file) == (tmp_path / "ca.pem", tmp_path / "ca-worker1.pem")
    arguments = second.extra_sim_arguments
    assert arguments[arguments.index("--disturbance-seed") + 1] == str(SEED + 1)
    fixed = CampaignOptions(stack, SEED, 1, default_level_values())
    assert trial_stack(fixed, SEED).world == Path("lab.yaml")


def test_a_failed_trials_layout_is_kept_beside_the_report(tmp_path: Path) -> None:
    layouts, report = tmp_path / "layouts", tmp_path / "report"
    layouts.mkdir()
    report.mkdir()
    outcomes = []
    for seed, success in ((1, True), (2, False)):
        world = layouts / f"layout_{seed}.yaml"
        world.write_text(f"name: lab {seed}\n")
        outcomes.append(
            TrialOutcome(seed, success, "" if success else "grasp", "", 1.0, 1.0, 1.0, None, world=str(world))
        )
    kept = keep_failed_layouts(outcomes, report)
    assert kept == [report / "layout_2.yaml"] and kept[0].read_text() == "name: lab 2\n"
    assert outcomes[1].world == str(kept[0]) and outcomes[0].world == str(layouts / "layout_1.yaml")


def test_save_layout_writes_the_trial_seeds_world_file(tmp_path: Path) -> None:
    target, seed = tmp_path / "lab.yaml", QUICK_DRAWN_SEED
    done = subprocess.run(
        [*CLI, "bench", "--save-layout", str(seed), str(target)], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert f"demo --world {target}" in done.stdout
    assert target.read_text() == layout_yaml(seed)
    assert load_world(target).name == f"random layout {seed}"


def test_save_layout_with_random_obstacles_writes_the_world_with_that_seeds_obstacles(tmp_path: Path) -> None:
    target = tmp_path / "lab.yaml"
    flags = [
        "bench",
        "--random-obstacles",
        "--world",
        str(DEFAULT_WORLD),
        "--save-layout",
        str(SEED),
        str(target),
    ]
    done = subprocess.run([*CLI, *flags], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert target.read_text() == furnished_yaml(DEFAULT_WORLD, SEED)
    world, base = load_world(target), load_world(DEFAULT_WORLD)
    assert world.obstacles and world.stations == base.stations


def test_random_layouts_and_random_obstacles_exclude_each_other() -> None:
    done = subprocess.run(
        [*CLI, "bench", "--random-layouts", "--random-obstacles"], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 2 and "exclude each other" in done.stderr


def test_a_random_obstacles_trial_replays_with_its_world() -> None:
    stack = DeploymentOptions(world=DEFAULT_WORLD, port_base=57000)
    options = CampaignOptions(
        stack, SEED, 1, default_level_values(), layouts_dir=Path("drawn"), layouts_flag="--random-obstacles"
    )
    assert replay_flags(options) == f" --random-obstacles --world {DEFAULT_WORLD}"
    assert replay_flags(CampaignOptions(stack, SEED, 1, default_level_values(), layouts_dir=Path("d"))) == (
        " --random-layouts"
    )


def test_random_layouts_on_two_workers_report_in_seed_order(tmp_path: Path) -> None:
    report = tmp_path / "report"
    flags = ["--random-layouts", "--trials", "2", "--jobs", "2", "--seed", str(SEED), "--json"]
    done = run_bench(*flags, "--report", str(report))
    assert done.stdout.strip(), done.stderr[-3000:]
    summary = json.loads(done.stdout)
    assert (summary["jobs"], summary["random_layouts"], summary["trials"]) == (2, True, 2)
    assert [outcome["seed"] for outcome in summary["outcomes"]] == [SEED, SEED + 1]
    assert summary["elapsed_wall_seconds"] > 0
    for outcome in summary["outcomes"]:
        assert Path(outcome["world"]).name == f"layout_{outcome['seed']}.yaml"
        if not outcome["success"]:  # its world file beside the report, the very layout of its seed
            assert Path(outcome["world"]).parent == report
            assert (
                yaml.safe_load(Path(outcome["world"]).read_text())["name"]
                == f"random layout {outcome['seed']}"
            )
    failed = {failure["seed"] for failure in summary["failed_trials"]}
    assert {int(path.stem.split("_")[1]) for path in report.glob("layout_*.yaml")} == failed
    assert done.returncode == (0 if not failed else 1)


def test_bench_help_names_the_layout_and_worker_flags() -> None:
    shown = subprocess.run([*CLI, "bench", "--help"], capture_output=True, text=True, timeout=60)
    text = " ".join(shown.stdout.split())
    for flag in ("--random-layouts", "--random-obstacles", "--save-layout SEED FILE", "--jobs JOBS"):
        assert flag in text, flag


def test_a_paced_campaigns_trial_replays_at_its_pace() -> None:
    stack = DeploymentOptions(world=DEFAULT_WORLD, port_base=57000, pace=1.0)
    assert replay_flags(CampaignOptions(stack, SEED, 1, default_level_values())) == " --pace 1"
    options = CampaignOptions(stack, SEED, 1, default_level_values())
    assert trial_stack(options, SEED + 1, worker=1).pace == 1.0
