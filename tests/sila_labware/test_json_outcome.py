"""Machine-readable always: a run that asked for JSON gets exactly one JSON object on stdout, even
when it is refused before its command starts (a missing or invalid world file, a bad option), with
the same `success`, `error`, `error_kind` and `exit_code` fields as a run that went through.

Through the installed `sila-labware` entry point, as a pipeline calls it."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from sila_labware.deployment.json_outcome import ERROR_KINDS, json_requested, outcome_fields
from tests.helpers.sila_stack import DEFAULT_WORLD

ENTRY_POINT = str(Path(sys.executable).with_name("sila-labware"))


def run(*arguments: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [ENTRY_POINT, *arguments], capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL
    )


def the_one_object(stdout: str) -> dict:
    """stdout holds one JSON object on one line, and nothing else."""
    lines = stdout.splitlines()
    assert len(lines) == 1, stdout
    document = json.loads(lines[0])
    assert isinstance(document, dict)
    return document


def assert_usage_failure(done: subprocess.CompletedProcess, reason: str) -> dict:
    assert done.returncode == 2, done.stderr
    document = the_one_object(done.stdout)
    assert document["success"] is False
    assert document["error_kind"] == "usage" and document["exit_code"] == 2
    assert reason in document["error"], document
    assert reason in done.stderr and done.stderr.startswith("sila-labware"), done.stderr
    return document


@pytest.mark.parametrize(
    ("arguments", "reason"),
    [
        (("demo", "--json", "--world", "/no/such/world.yaml"), "world file not found: /no/such/world.yaml"),
        (("demo", "--json", "--bogus"), "unrecognized arguments: --bogus"),
        (("demo", "--json", "--pace", "fast"), "argument --pace: invalid float value: 'fast'"),
        (("demo", "--jso", "--domain-id", "999"), "--domain-id 999 is outside 0..232"),  # abbreviated
        (("--json",), "the following arguments are required"),
        (("bench", "--json", "--trials", "0"), "--trials 0: need at least one"),
        (("serve", "--print-config", "json", "--port-base", "0"), "--port-base 0 is not a usable port"),
        (("serve", "--print-config=yaml"), "invalid choice: 'yaml'"),
    ],
)
def test_a_refused_json_run_prints_one_object_saying_why(arguments: tuple[str, ...], reason: str) -> None:
    assert_usage_failure(run(*arguments), reason)


def test_demo_json_with_an_invalid_world_names_every_problem_in_its_object(tmp_path: Path) -> None:
    world = yaml.safe_load(DEFAULT_WORLD.read_text())
    world["stations"][1]["marker"]["id"] = world["stations"][0]["marker"]["id"]
    world["plates"][0]["station"] = "nowhere"
    bad = tmp_path / "bad_world.yaml"
    bad.write_text(yaml.safe_dump(world))
    document = assert_usage_failure(run("demo", "--json", "--world", str(bad)), "invalid world file:")
    assert "plates[0].station" in document["error"] and "unknown station" in document["error"]
    assert "stations[1].marker.id" in document["error"], document["error"]


def test_without_json_a_refusal_keeps_stdout_empty() -> None:
    done = run("demo", "--world", "/no/such/world.yaml")
    assert (done.returncode, done.stdout) == (2, "")
    assert done.stderr == "sila-labware: error: world file not found: /no/such/world.yaml\n"


def test_bench_save_layout_json_names_the_file_it_wrote(tmp_path: Path) -> None:
    target = tmp_path / "layout.yaml"
    done = run("bench", "--save-layout", "5162", str(target), "--json")  # drawn in under a second
    assert done.returncode == 0, done.stderr
    assert the_one_object(done.stdout) == {
        "layout": str(target),
        "seed": 5162,
        "success": True,
        "error": "",
        "error_kind": "",
        "exit_code": 0,
    }
    assert yaml.safe_load(target.read_text())["stations"], "a world file with stations"


@pytest.mark.parametrize(
    ("argv", "wanted"),
    [
        (["demo", "--json"], True),
        (["demo", "--js"], True),
        (["demo", "--json=1"], True),
        (["serve", "--print-config", "json"], True),
        (["serve", "--print"], True),
        (["demo", "--world", "w.yaml"], False),
        (["demo", "--", "--json"], False),
        (["serve", "--pace", "2"], False),  # "--p" alone could be --pace or --port-base
        (["serve", "--p"], False),
    ],
)
def test_json_requested_reads_the_flags_as_argparse_would(argv: list[str], wanted: bool) -> None:
    assert json_requested(argv) is wanted


def test_outcome_fields_refuse_an_inconsistent_outcome() -> None:
    assert outcome_fields("no robot", "start_failed", 1)["success"] is False
    assert set(ERROR_KINDS) == {"usage", "start_failed", "failed", "interrupted", "internal"}
    with pytest.raises(ValueError, match="unknown error kind 'oops'"):
        outcome_fields("broken", "oops", 1)
    with pytest.raises(ValueError, match="needs its kind"):
        outcome_fields("broken", "", 1)
    with pytest.raises(ValueError, match="needs its kind"):
        outcome_fields("", "failed", 1)
