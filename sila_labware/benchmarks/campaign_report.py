"""Pictures for a campaign report: charts of the success table and phase times, and one run's frames.

Charts are drawn with matplotlib (a `Figure` on the Agg canvas: headless, and no pyplot, so no
global figure state is touched when a campaign writes its report); the camera pictures (image
strip, GIF) with OpenCV, which reads and resizes the recorded frames. This is a reporting tool
beside the device stack: nothing on the SiLA -> ROS path imports it, so the rule "sila_labware
never imports cv2" holds for the device itself; cv2 and matplotlib are imported only when a
report is written.

Frames come from the sim node's run recorder (tiago_sim.measuring.run_recorder): ``overview_NNNN.png`` and
``head_NNNN.png`` (head frames with the detected marker outlined).
Threads: any; pure file in, file out.
"""

from __future__ import annotations

import logging
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

logger = logging.getLogger(__name__)

DELIVERED_COLOUR = "#3b8f3b"
FAILED_COLOUR = "#c44536"
SIMULATED_COLOUR = "#2f6fad"
WALL_COLOUR = "#a5a5a5"
INK = "#333333"
FAINT = "#dddddd"
CHART_DPI = 150
PHASE_LABEL_WIDTH = 24  # characters per line before a phase name wraps (at its " + ")


def _cv2() -> Any:
    import cv2

    return cv2


def _figure(width_in: float, height_in: float) -> Figure:
    """A figure on its own Agg canvas, independent of pyplot's current figure and backend."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width_in, height_in), dpi=CHART_DPI, layout="constrained")
    FigureCanvasAgg(figure)
    figure.set_facecolor("white")
    return figure


def _style(axes: Axes, title: str) -> None:
    """Horizontal bars read top-down; a light grid along the values, no box."""
    axes.set_title(title, loc="left", fontsize=10, color=INK, fontweight="bold")
    axes.invert_yaxis()
    axes.grid(axis="x", color=FAINT, linewidth=0.8)
    axes.set_axisbelow(True)
    for side in ("top", "right", "left"):
        axes.spines[side].set_visible(False)
    axes.spines["bottom"].set_color("#999999")
    axes.tick_params(axis="y", length=0, labelsize=9, labelcolor=INK)
    axes.tick_params(axis="x", labelsize=8, colors="#666666")


def _label_bars(axes: Axes, bars: Any, texts: list[str]) -> None:
    """The value beside each bar's end, inside the axes (the x range leaves room for it)."""
    for bar, text in zip(bars, texts, strict=True):
        axes.annotate(
            text,
            (bar.get_width(), bar.get_y() + bar.get_height() / 2),
            xytext=(4, 0),
            textcoords="offset points",
            va="center",
            fontsize=8,
            color=INK,
        )


def success_chart(summary: dict[str, Any]) -> Figure:
    """Left: delivered against failed, of all trials. Right: the failures by cause, on a scale
    of their own, so that one failure in two hundred is still visible."""
    from matplotlib.ticker import MaxNLocator

    trials, successes = int(summary["trials"]), int(summary["successes"])
    failures = {cause: int(count) for cause, count in summary["failures"].items()}
    figure = _figure(9.0, 3.0)
    outcome_axes, cause_axes = figure.subplots(1, 2, width_ratios=(1.0, 1.1))
    figure.suptitle(
        f"{trials} transfers, {successes} delivered ({100 * summary['success_rate']:.1f} %), "
        f"seed {summary['seed']}",
        x=0.01,
        ha="left",
        fontsize=11,
        color=INK,
    )

    outcomes = [successes, trials - successes]
    bars = outcome_axes.barh(
        ["delivered", "failed"], outcomes, color=[DELIVERED_COLOUR, FAILED_COLOUR], height=0.55
    )
    _style(outcome_axes, "outcome")
    outcome_axes.set_xlim(0, max(trials, 1) * 1.18)
    outcome_axes.set_xlabel("trials", fontsize=8, color="#666666")
    outcome_axes.xaxis.set_major_locator(MaxNLocator(nbins=5, integer=True))
    _label_bars(
        outcome_axes,
        bars,
        [f"{count} ({100 * count / trials:.1f} %)" if trials else "0" for count in outcomes],
    )

    causes = list(failures)
    bars = cause_axes.barh(causes, [failures[c] for c in causes], color=FAILED_COLOUR, height=0.55)
    _style(cause_axes, "failures by cause")
    cause_axes.set_xlim(0, max(max(failures.values(), default=0), 1) * 1.25)
    cause_axes.set_xlabel("trials", fontsize=8, color="#666666")
    cause_axes.xaxis.set_major_locator(MaxNLocator(nbins=4, integer=True))
    _label_bars(cause_axes, bars, [str(failures[c]) for c in causes])
    return figure


def _phase_label(name: str) -> str:
    """Long phase names ("A.PrepareForOutput + Robot.PrepareForInput") on two lines."""
    return "\n".join(textwrap.wrap(name, PHASE_LABEL_WIDTH, break_on_hyphens=False)) or name


def _seconds(value: float) -> str:
    """Bar labels: a station's instant step shows as 0.03 s, not as 0.0 s."""
    return f"{value:.2f} s" if 0 < value < 0.095 else f"{value:.1f} s"


def phase_chart(summary: dict[str, Any]) -> Figure:
    """Median simulated and wall seconds per phase of the standard sequence, and for the whole
    transfer (delivered trials), as paired bars."""
    phases = summary["phases"]
    labels = [_phase_label(name) for name in phases] + ["whole transfer\n(delivered)"]
    simulated = [phases[name]["sim_seconds_median"] for name in phases] + [summary["sim_seconds_median"]]
    wall = [phases[name]["wall_seconds_median"] for name in phases] + [summary["wall_seconds_median"]]
    figure = _figure(9.0, 0.55 * len(labels) + 1.3)
    axes = figure.subplots()
    factor = summary["realtime_factor"]
    figure.suptitle(
        f"Median time per phase, simulated and wall clock (real-time factor {factor:.1f})",
        x=0.01,
        ha="left",
        fontsize=11,
        color=INK,
    )
    rows = np.arange(len(labels))
    height = 0.38
    for offset, values, colour, name in (
        (-height / 2, simulated, SIMULATED_COLOUR, "simulated"),
        (height / 2, wall, WALL_COLOUR, "wall clock"),
    ):
        bars = axes.barh(rows + offset, values, height=height, color=colour, label=name)
        _label_bars(axes, bars, [_seconds(value) for value in values])
    _style(axes, "")
    axes.set_yticks(rows, labels)
    axes.set_xlim(0, max(simulated + wall + [1.0]) * 1.12)
    axes.set_xlabel("seconds (median over trials)", fontsize=8, color="#666666")
    if len(labels) > 1:  # the whole transfer is a sum, not a phase: set it apart
        axes.axhline(len(labels) - 1.5, color="#999999", linewidth=0.8, linestyle=(0, (4, 3)))
    axes.legend(loc="upper right", fontsize=8, frameon=False)
    return figure


def _frames(directory: Path, prefix: str) -> list[Path]:
    return sorted(directory.glob(f"{prefix}_*.png"))


def _evenly(paths: list[Path], count: int) -> list[Path]:
    if len(paths) <= count:
        return paths
    picks = np.linspace(0, len(paths) - 1, count).round().astype(int)
    return [paths[i] for i in picks]


def _tile(images: list[np.ndarray], size: tuple[int, int]) -> np.ndarray:
    cv2 = _cv2()
    width, height = size
    tiles = [cv2.resize(image, (width, height), interpolation=cv2.INTER_AREA) for image in images]
    return np.hstack(tiles) if tiles else np.full((height, width, 3), 255, np.uint8)


def run_strip(frames_dir: Path, columns: int = 5) -> np.ndarray | None:
    """Top row: overview camera over the run; bottom row: head camera with the marker outlined."""
    cv2 = _cv2()
    overview = [cv2.imread(str(p)) for p in _evenly(_frames(frames_dir, "overview"), columns)]
    head = [cv2.imread(str(p)) for p in _evenly(_frames(frames_dir, "head"), columns)]
    if not overview and not head:
        return None
    tile = (320, 240)
    rows = [_tile(overview, tile), _tile(head, tile)]
    width = max(r.shape[1] for r in rows)
    rows = [np.hstack([r, np.full((r.shape[0], width - r.shape[1], 3), 255, np.uint8)]) for r in rows]
    return np.vstack(rows)


def write_run_pictures(frames_dir: Path, out_dir: Path) -> list[Path]:
    """`run_strip.png` and `run.gif` (overview frames) from a recorded run; returns what was written."""
    cv2 = _cv2()
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    strip = run_strip(frames_dir)
    if strip is not None:
        path = out_dir / "run_strip.png"
        cv2.imwrite(str(path), strip)
        written.append(path)
    overview = _frames(frames_dir, "overview")
    if overview:
        animation = cv2.Animation()
        animation.frames = [
            cv2.resize(cv2.imread(str(p)), (320, 240), interpolation=cv2.INTER_AREA)
            for p in _evenly(overview, 30)
        ]
        animation.durations = [300] * len(animation.frames)
        animation.loop_count = 0
        path = out_dir / "run.gif"
        if cv2.imwriteanimation(str(path), animation):
            written.append(path)
        else:
            logger.warning("could not write %s", path)
    return written


def write_charts(summary: dict[str, Any], out_dir: Path) -> list[Path]:
    """`success_by_cause.png` and `time_per_phase.png`."""
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for name, figure in (
        ("success_by_cause.png", success_chart(summary)),
        ("time_per_phase.png", phase_chart(summary)),
    ):
        path = out_dir / name
        figure.savefig(path, dpi=CHART_DPI, facecolor="white")
        written.append(path)
    return written
