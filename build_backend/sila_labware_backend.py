"""PEP 517 build backend: setuptools' wheel plus our ROS 2 interface package, built at install.

Why: `pip install <clone or git URL>` into any venv must give a working `sila-labware`, and the
robot's actions (labware_interfaces) are C-backed ROS 2 types that only a CMake build makes. The
ROS 2 Jazzy wheels on PyPI carry everything that build needs; pip installs them into the isolated
build environment (`[build-system] requires`), this backend runs the build there and puts its
output into the wheel as the ROS wheels put theirs: the Python package at the wheel's root, the
libraries and the ament index under the install prefix (`<dist>.data/data/{lib,share}`), where
the ROS wheels' start-up hook already puts the library path. The wheel is then platform-specific.

Editable installs (`./run setup`) stay setuptools' own: `./run` builds the interfaces into its venv.
"""

from __future__ import annotations

import base64
import hashlib
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time
import zipfile
from importlib import metadata
from pathlib import Path

from setuptools import build_meta as _setuptools
from setuptools.build_meta import (  # noqa: F401 - the hooks pip calls besides build_wheel
    build_editable,
    build_sdist,
    get_requires_for_build_editable,
    get_requires_for_build_sdist,
    get_requires_for_build_wheel,
    prepare_metadata_for_build_editable,
    prepare_metadata_for_build_wheel,
)

ROOT = Path(__file__).resolve().parents[1]
INTERFACES = ROOT / "ros_bridge" / "interfaces" / "labware_interfaces"
PACKAGE = "labware_interfaces"
MANYLINUX_PATHS = re.compile(
    r"/opt/python/cp3\d+-cp3\d+/(?:lib/python3\.\d+/site-packages/numpy/_core/include|include/python3\.\d+)"
)


def build_wheel(
    wheel_directory: str, config_settings: dict | None = None, metadata_directory: str | None = None
) -> str:
    name = _setuptools.build_wheel(wheel_directory, config_settings, metadata_directory)
    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="labware_interfaces_") as scratch:
        installed = _build_interfaces(Path(scratch))
        built = _add_to_wheel(Path(wheel_directory) / name, installed)
    # pip shows a backend's output with -v; the fresh-install benchmark reads this line
    print(f"labware_interfaces built into the wheel in {time.monotonic() - started:.1f} s", file=sys.stderr)
    return built


def _ros_prefix() -> Path:
    """The prefix the ROS build packages were installed under (their share/ and lib/)."""
    for distribution in metadata.distributions():
        for file in distribution.files or []:
            if str(file).endswith("share/ament_cmake_core/cmake/ament_cmake_coreConfig.cmake"):
                located = Path(str(file.locate())).resolve()
                return located.parents[3]  # <prefix>/share/ament_cmake_core/cmake/<file>
    raise RuntimeError("no installed ROS package carries ament_cmake_core's CMake files")


def _fix_cmake_paths(prefix: Path) -> None:
    """The ROS wheels' CMake files name include dirs of the image they were built in; point them
    at this interpreter's headers and numpy's."""
    import numpy

    python_include = sysconfig.get_paths()["include"]

    def local(match: re.Match) -> str:
        return numpy.get_include() if "numpy" in match.group(0) else python_include

    for cmake_file in (prefix / "share").rglob("*.cmake"):
        text = cmake_file.read_text(errors="replace")
        fixed = MANYLINUX_PATHS.sub(local, text)
        if fixed != text:
            cmake_file.write_text(fixed)


def _cmake() -> str:
    try:
        import cmake  # the PyPI package, from [build-system] requires

        return str(Path(cmake.CMAKE_BIN_DIR) / "cmake")
    except ImportError:
        found = shutil.which("cmake")
        if found is None:
            raise RuntimeError("building labware_interfaces needs cmake") from None
        return found


def _build_interfaces(scratch: Path) -> Path:
    """CMake-build the interface package against the ROS prefix; returns its install prefix."""
    prefix = _ros_prefix()
    _fix_cmake_paths(prefix)
    build, install = scratch / "build", scratch / "install"
    environment = dict(os.environ)
    environment["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), environment.get("PATH", "")])
    library_path = [str(prefix / "lib"), environment.get("LD_LIBRARY_PATH", "")]
    environment["LD_LIBRARY_PATH"] = os.pathsep.join(library_path)
    environment["AMENT_PREFIX_PATH"] = str(prefix)
    cmake = _cmake()
    steps = [
        [
            cmake, "-S", str(INTERFACES), "-B", str(build),
            f"-DCMAKE_PREFIX_PATH={prefix}", f"-DCMAKE_INSTALL_PREFIX={install}",
            f"-DPython3_EXECUTABLE={sys.executable}", "-DBUILD_TESTING=OFF", "-DCMAKE_BUILD_TYPE=Release",
        ],
        [cmake, "--build", str(build), f"-j{os.cpu_count() or 1}"],
        [cmake, "--install", str(build)],
    ]  # fmt: skip
    log = scratch / "build.log"
    with log.open("w") as output:
        for step in steps:
            done = subprocess.run(step, stdout=output, stderr=subprocess.STDOUT, env=environment, check=False)
            if done.returncode != 0:
                tail = log.read_text(errors="replace").splitlines()[-40:]
                raise RuntimeError("building labware_interfaces failed:\n" + "\n".join(tail))
    return install


def _record_line(arcname: str, data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{arcname},sha256={digest},{len(data)}"


def _add_to_wheel(wheel: Path, installed: Path) -> str:
    """A platform wheel: the pure one plus the interface package's Python module, libraries and
    share/ files; returns its file name."""
    distribution, version = wheel.name.split("-")[:2]
    data_dir = f"{distribution}-{version}.data/data"
    site_packages = next(installed.glob("lib/python3*/site-packages"))
    additions: dict[str, bytes] = {}
    for path in sorted((site_packages / PACKAGE).rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts:
            additions[f"{PACKAGE}/{path.relative_to(site_packages / PACKAGE).as_posix()}"] = path.read_bytes()
    for top in ("lib", "share"):
        for path in sorted((installed / top).rglob("*")):
            if path.is_file() and "site-packages" not in path.parts and not path.name.endswith(".pyc"):
                additions[f"{data_dir}/{path.relative_to(installed).as_posix()}"] = path.read_bytes()
    tag = f"cp{sys.version_info.major}{sys.version_info.minor}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    target = wheel.with_name(f"{distribution}-{version}-{tag}-{tag}-{platform}.whl")
    info = f"{distribution}-{version}.dist-info"
    records: list[str] = []
    with zipfile.ZipFile(wheel) as source, zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as out:
        for item in source.infolist():
            if item.filename in (f"{info}/RECORD", f"{info}/WHEEL"):
                continue
            data = source.read(item)
            out.writestr(item, data)
            records.append(_record_line(item.filename, data))
        wheel_text = source.read(f"{info}/WHEEL").decode()
        wheel_text = re.sub(r"Root-Is-Purelib: true", "Root-Is-Purelib: false", wheel_text)
        wheel_text = re.sub(r"Tag: .*", f"Tag: {tag}-{tag}-{platform}", wheel_text)
        for arcname, data in additions.items():
            info_entry = zipfile.ZipInfo(arcname, date_time=(2026, 1, 1, 0, 0, 0))
            info_entry.external_attr = 0o755 << 16 if arcname.endswith(".so") else 0o644 << 16
            out.writestr(info_entry, data)
            records.append(_record_line(arcname, data))
        out.writestr(f"{info}/WHEEL", wheel_text)
        records.append(_record_line(f"{info}/WHEEL", wheel_text.encode()))
        records.append(f"{info}/RECORD,,")
        out.writestr(f"{info}/RECORD", "\n".join(records) + "\n")
    wheel.unlink()
    return target.name
