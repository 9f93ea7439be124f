"""Regenerate the `generated/` trees of our SiLA server packages from the definitions in features/.

Why: `generated/` must always be exactly what sila2's code generator makes from features/*.sila.xml, and
regenerating must never touch the hand-written side (server.py, __main__.py, feature_implementations/).
So the generator writes a complete package into a temporary directory and only its `generated/` tree is
copied over. A package that does not exist yet is created whole (the one-time scaffold); an
implementation file for a newly added feature is added, never overwritten.

    python -m sila_labware.servers.codegen            regenerate every package's generated/ tree
    python -m sila_labware.servers.codegen --check    exit 1 and name the files if a committed tree is stale
"""

from __future__ import annotations

import argparse
import contextlib
import filecmp
import logging
import os
import shutil
import sys
import tempfile
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path

logger = logging.getLogger(__name__)

PACKAGES_DIR = Path(__file__).resolve().parent
FEATURES_DIR = PACKAGES_DIR.parents[1] / "features"

# Package name (a subpackage of sila_labware) -> feature definition files it serves, from features/.
SERVER_FEATURES: dict[str, tuple[str, ...]] = {
    "robot_server": (
        "LabwareTransferManipulatorController.sila.xml",
        "MobileRobotController.sila.xml",
        "LabwareInventory.sila.xml",
        "CancelController.sila.xml",
        "SimulationController.sila.xml",
        "SimulatedLabController.sila.xml",
    ),
    "station_server": ("LabwareTransferSiteController.sila.xml", "SimulationController.sila.xml"),
}

# Written by Python or the tools while the tree is used; never part of the generated content.
_IGNORED_NAMES = frozenset({"__pycache__", ".DS_Store"})


@contextlib.contextmanager
def _working_directory(path: Path) -> Iterator[None]:
    """Run isort/black (which look for configuration from the cwd) away from any project config."""
    previous = Path.cwd()
    os.chdir(path)
    try:
        yield
    finally:
        os.chdir(previous)


def generate_package(package_name: str, fdl_paths: Sequence[Path], out_dir: Path) -> Path:
    """Write a complete sila2-codegen package into `out_dir` and return the package's directory.

    Same steps as `sila2-codegen new-package`, but called in-process so that errors raise (the command
    line tool prints them and still exits 0).
    """
    from sila2.code_generator.code_generator import CodeGenerator
    from sila2.framework.feature import Feature

    features = [Feature(str(path)) for path in sorted(fdl_paths, key=str)]
    out_dir.mkdir(parents=True, exist_ok=True)
    generator = CodeGenerator(overwrite=True)
    with _working_directory(out_dir):
        generator.generate_package(package_name, features, str(out_dir), generate_main=True)
        generator.format_generated_files()
    return out_dir / package_name


def _relative_files(tree: Path) -> set[Path]:
    """All files below `tree`, relative to it, without caches."""
    return {
        path.relative_to(tree)
        for path in tree.rglob("*")
        if path.is_file() and not _IGNORED_NAMES.intersection(path.relative_to(tree).parts)
    }


def differing_files(expected_tree: Path, actual_tree: Path) -> list[str]:
    """Relative paths that are missing, extra or different in `actual_tree` compared to `expected_tree`."""
    expected = _relative_files(expected_tree)
    actual = _relative_files(actual_tree) if actual_tree.is_dir() else set()
    differences = [f"missing: {path}" for path in sorted(expected - actual)]
    differences += [f"unexpected: {path}" for path in sorted(actual - expected)]
    differences += [
        f"differs: {path}"
        for path in sorted(expected & actual)
        if not filecmp.cmp(expected_tree / path, actual_tree / path, shallow=False)
    ]
    return differences


def _fdl_paths(feature_files: Sequence[str], features_dir: Path) -> list[Path]:
    return [features_dir / name for name in feature_files]


def _install_package(fresh_package: Path, target_package: Path) -> None:
    """Replace `generated/` of the target; add scaffold files only where none exist yet."""
    if not target_package.exists():
        logger.info("creating new package %s", target_package)
        shutil.copytree(fresh_package, target_package)
        return
    target_generated = target_package / "generated"
    if target_generated.exists():
        shutil.rmtree(target_generated)
    shutil.copytree(fresh_package / "generated", target_generated)
    for impl_file in sorted((fresh_package / "feature_implementations").glob("*_impl.py")):
        target_impl = target_package / "feature_implementations" / impl_file.name
        if not target_impl.exists():
            shutil.copy2(impl_file, target_impl)
            logger.warning("added %s: register the new feature in %s/server.py", target_impl, target_package)


def _fresh_packages(
    features_dir: Path, server_features: Mapping[str, Sequence[str]]
) -> Iterator[tuple[str, Sequence[str], Path]]:
    """Generate each server package into a temporary directory: (name, feature files, package dir)."""
    for package_name, feature_files in server_features.items():
        with tempfile.TemporaryDirectory(prefix=f"codegen-{package_name}-") as tmp:
            fresh = generate_package(package_name, _fdl_paths(feature_files, features_dir), Path(tmp))
            yield package_name, feature_files, fresh


def regenerate(
    packages_dir: Path = PACKAGES_DIR,
    features_dir: Path = FEATURES_DIR,
    server_features: Mapping[str, Sequence[str]] = SERVER_FEATURES,
) -> list[Path]:
    """Regenerate every package's generated/ tree from features/; return the package directories."""
    written = []
    for package_name, feature_files, fresh in _fresh_packages(features_dir, server_features):
        target = packages_dir / package_name
        _install_package(fresh, target)
        logger.info("regenerated %s/generated from %s", target, ", ".join(feature_files))
        written.append(target)
    return written


def stale_files(
    packages_dir: Path = PACKAGES_DIR,
    features_dir: Path = FEATURES_DIR,
    server_features: Mapping[str, Sequence[str]] = SERVER_FEATURES,
) -> list[str]:
    """Files of the committed generated/ trees that differ from a fresh generation (empty: up to date)."""
    problems = []
    for package_name, _feature_files, fresh in _fresh_packages(features_dir, server_features):
        committed = packages_dir / package_name / "generated"
        problems += [
            f"{package_name}/generated: {difference}"
            for difference in differing_files(fresh / "generated", committed)
        ]
    return problems


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m sila_labware.servers.codegen", description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        "--check", action="store_true", help="do not write; exit 1 if a generated/ tree is out of date"
    )
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    if args.check:
        problems = stale_files()
        for problem in problems:
            logger.error("%s", problem)
        if problems:
            logger.error("generated code is stale: run `python -m sila_labware.servers.codegen`")
            return 1
        logger.info("generated code is up to date")
        return 0
    regenerate()
    return 0


if __name__ == "__main__":
    sys.exit(main())
