"""One campaign trial as it runs on a Ray node: the same `run_trial` as `bench --jobs`, made whole there.

Why a module of its own: the node may be another machine. Nothing of the driver's file system is
there, so the task carries what the trial reads (the world file, the trial's random layout) as
text and writes it into a scratch folder of the node's; it sends back what the report needs (the
recorded frames of the campaign's first trial) as bytes. No one numbers the trials of one host
(two Ray nodes may share a host), so the process reserves its SiLA ports and its ROS domain with
host-wide locks (port_blocks, ros_bridge.domain), held while the Ray worker process lives; the
robot side keeps its DDS traffic on the host (processes.ros_environment: localhost discovery).
The outcome names the driver's world path, as a `--jobs` run's does: only `node` tells where it ran.

Threads: the Ray worker's task thread, one trial at a time per worker process (one CPU per task).
"""

from __future__ import annotations

import logging
import shutil
import socket
import tempfile
from dataclasses import dataclass, field, replace
from pathlib import Path

from sila_labware.benchmarks.campaign import (
    PORTS_PER_WORKER,
    CampaignOptions,
    TrialOutcome,
    layout_path,
    run_trial,
)
from sila_labware.benchmarks.stop_deadline import STOP_DEADLINE_S
from sila_labware.benchmarks.workers import prepare_trial_process
from sila_labware.deployment.port_blocks import reserve_port_block

logger = logging.getLogger(__name__)

_prepared = False  # in a Ray worker process: whether it was set up for trials


@dataclass(frozen=True)
class TrialFiles:
    """What a trial reads from the driver's disk, as text: the world file and its seed's layout."""

    world_name: str
    world_text: str
    layout_text: str | None = None  # with --random-layouts / --random-obstacles

    @classmethod
    def of(cls, options: CampaignOptions, trial_seed: int) -> TrialFiles:
        layout = None
        if options.layouts_dir is not None:
            layout = layout_path(options.layouts_dir, trial_seed).read_text()
        return cls(options.stack.world.name, options.stack.world.read_text(), layout)


@dataclass(frozen=True)
class NodeResult:
    """What a Ray task sends back: the outcome (with the node that ran it), the frames it recorded."""

    outcome: TrialOutcome
    frames: dict[str, bytes] = field(default_factory=dict)


def run_trial_on_node(
    options: CampaignOptions, trial_seed: int, files: TrialFiles, record: bool, levels: dict[str, int]
) -> NodeResult:
    """Run one trial in this (Ray worker) process with the node's own copies of its files, ports and
    ROS domain; `record`: keep the run's frames for the report."""
    global _prepared
    if not _prepared:
        prepare_trial_process(levels)
        _prepared = True
    scratch = Path(tempfile.mkdtemp(prefix="sila-labware-trial-"))
    try:
        local = options_on_node(options, trial_seed, files, scratch)
        frames_dir = scratch / "frames" if record else None
        outcome = run_trial(local, trial_seed, frames_dir, stop_deadline_s=STOP_DEADLINE_S)
        layouts = options.layouts_dir
        world = options.stack.world if layouts is None else layout_path(layouts, trial_seed)
        frames = _read_frames(frames_dir)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return NodeResult(replace(outcome, world=str(world), node=_node_name()), frames)


def options_on_node(
    options: CampaignOptions, trial_seed: int, files: TrialFiles, scratch: Path
) -> CampaignOptions:
    """The campaign's options with this node's world file, layout, CA file, ports and ROS domain."""
    world = scratch / files.world_name
    world.write_text(files.world_text)
    layouts_dir = None
    if files.layout_text is not None:
        layouts_dir = scratch / "layouts"
        layouts_dir.mkdir()
        layout_path(layouts_dir, trial_seed).write_text(files.layout_text)
    port_base = reserve_port_block(options.stack.port_base, PORTS_PER_WORKER, options.stack.host)
    stack = replace(
        options.stack,
        world=world,
        ca_file=scratch / "sila-labware-ca.pem",
        port_base=port_base,
        domain_id=None,  # this process's own, reserved host-wide (ros_bridge.domain)
    )
    return replace(options, stack=stack, layouts_dir=layouts_dir, record_dir=None, jobs=1)


def _read_frames(frames_dir: Path | None) -> dict[str, bytes]:
    if frames_dir is None or not frames_dir.is_dir():
        return {}
    return {path.name: path.read_bytes() for path in sorted(frames_dir.iterdir()) if path.is_file()}


def _node_name() -> str:
    import ray

    return f"{socket.gethostname()}/{ray.get_runtime_context().get_node_id()[:12]}"
