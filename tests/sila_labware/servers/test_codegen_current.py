"""The committed generated/ trees are exactly what sila2's code generator makes from features/.

Why: generated code that drifts from the feature definitions serves a different interface than the one
the definitions (and the conformance tests) describe.
Fix a failure with `python -m sila_labware.servers.codegen`.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from sila_labware.servers import codegen


def test_committed_generated_trees_are_current() -> None:
    stale = codegen.stale_files()
    assert stale == [], (
        "generated code is stale (run `python -m sila_labware.servers.codegen`):\n" + "\n".join(stale)
    )


@pytest.fixture
def package_copies(tmp_path: Path) -> Path:
    """A throw-away copy of both server packages, so that the real tree is never written to."""
    for package_name in codegen.SERVER_FEATURES:
        shutil.copytree(
            codegen.PACKAGES_DIR / package_name,
            tmp_path / package_name,
            ignore=shutil.ignore_patterns("__pycache__"),
        )
    return tmp_path


def test_check_names_every_kind_of_drift(package_copies: Path) -> None:
    generated = package_copies / "robot_server" / "generated"
    (generated / "client.py").write_text("# edited by hand\n", encoding="utf-8")
    (generated / "mobilerobotcontroller" / "mobilerobotcontroller_types.py").unlink()
    (generated / "stray.py").write_text("", encoding="utf-8")

    stale = codegen.stale_files(packages_dir=package_copies)

    assert stale == [
        "robot_server/generated: missing: mobilerobotcontroller/mobilerobotcontroller_types.py",
        "robot_server/generated: unexpected: stray.py",
        "robot_server/generated: differs: client.py",
    ]


def test_regeneration_restores_generated_and_keeps_hand_written_files(package_copies: Path) -> None:
    robot = package_copies / "robot_server"
    (robot / "generated" / "client.py").write_text("# edited by hand\n", encoding="utf-8")
    hand_written = {
        path: path.read_bytes()
        for path in [
            robot / "server.py",
            robot / "__main__.py",
            *(robot / "feature_implementations").glob("*.py"),
        ]
    }
    impl_file = robot / "feature_implementations" / "mobilerobotcontroller_impl.py"
    impl_file.write_text(impl_file.read_text(encoding="utf-8") + "\n# our behaviour\n", encoding="utf-8")
    hand_written[impl_file] = impl_file.read_bytes()

    codegen.regenerate(packages_dir=package_copies)

    assert codegen.stale_files(packages_dir=package_copies) == []
    for path, content in hand_written.items():
        assert path.read_bytes() == content, f"regeneration touched hand-written {path.name}"
