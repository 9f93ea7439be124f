"""Pictures for a campaign report: charts of the success table and phase times, and one run's frames.

Why OpenCV: it is already a dependency (matplotlib is not), and bar charts need only rectangles
and text. This is a reporting tool beside the device stack: nothing on the SiLA -> ROS path
imports it, so the rule "sila_labware never imports cv2" holds for the device itself; cv2 is
imported only when a report is written.

Frames come from the sim node's run recorder (tiago_sim.measuring.run_recorder): ``overview_NNNN.png`` and
``head_NNNN.png`` (head frames with the detected marker outlined).
Threads: any; pure file in, file out.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import numpy as np

logger = logging.getLogger(__name__)

WHITE = (255, 255, 255)
INK = (40, 40, 40)
GREEN = (80, 170, 60)
RED = (60, 60, 200)  # BGR
BLUE = (190, 120, 40)
GREY = (170, 170, 170)
FONT = 0  # cv2.FONT_HERSHEY_SIMPLEX


def _cv2() -> Any:
    import cv2

    return cv2


def _text(canvas: np.ndarray, text: str, origin: tuple[int, int], scale: float = 0.5, color=INK) -> None:
    _cv2().putText(canvas, text, origin, FONT, scale, color, 1, _cv2().LINE_AA)


def _bar_chart(
    title: str, labels: list[str], series: list[tuple[str, Any, list[float]]], unit: str
) -> np.ndarray:
    """Horizontal bars, one group per label, one bar per series (name, BGR colour, values)."""
    cv2 = _cv2()
    row = 18 * len(series) + 14
    width, left, right, top = 760, 330, 90, 60
    height = top + row * len(labels) + 40
    canvas = np.full((height, width, 3), 255, np.uint8)
    _text(canvas, title, (12, 26), 0.62)
    largest = max((v for _, _, values in series for v in values), default=1.0) or 1.0
    scale = (width - left - right) / largest
    for legend_index, (name, color, _) in enumerate(series):
        x = 12 + 190 * legend_index
        cv2.rectangle(canvas, (x, 38), (x + 14, 50), color[0] if isinstance(color, list) else color, -1)
        _text(canvas, name, (x + 20, 50), 0.45)
    for index, label in enumerate(labels):
        y0 = top + index * row
        _text(canvas, label[:44], (12, y0 + row // 2 + 4), 0.45)
        for series_index, (_, color, values) in enumerate(series):
            value = values[index]
            y = y0 + 4 + 18 * series_index
            bar_color = color[index] if isinstance(color, list) else color
            cv2.rectangle(canvas, (left, y), (left + max(1, int(value * scale)), y + 14), bar_color, -1)
            _text(canvas, f"{value:g} {unit}".strip(), (left + int(value * scale) + 6, y + 12), 0.42)
    cv2.line(canvas, (left, top - 4), (left, height - 36), GREY, 1)
    return canvas


def success_chart(summary: dict[str, Any]) -> np.ndarray:
    failures = summary["failures"]
    labels = ["delivered"] + [f"failed: {cause}" for cause in failures]
    counts = [float(summary["successes"])] + [float(count) for count in failures.values()]
    title = (
        f"{summary['trials']} transfers, {summary['successes']} delivered "
        f"({100 * summary['success_rate']:.1f} %), seed {summary['seed']}"
    )
    colors = [GREEN] + [RED] * len(failures)
    return _bar_chart(title, labels, [("trials", colors, counts)], "")


def phase_chart(summary: dict[str, Any]) -> np.ndarray:
    phases = summary["phases"]
    labels = list(phases) + ["whole transfer"]
    sim = [round(phases[n]["sim_seconds_median"], 1) for n in phases] + [
        round(summary["sim_seconds_median"], 1)
    ]
    wall = [round(phases[n]["wall_seconds_median"], 1) for n in phases] + [
        round(summary["wall_seconds_median"], 1)
    ]
    title = f"median time per phase (real-time factor {summary['realtime_factor']:.1f})"
    return _bar_chart(title, labels, [("simulated s", BLUE, sim), ("wall s", GREY, wall)], "s")


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
    cv2 = _cv2()
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for name, image in (
        ("success_by_cause.png", success_chart(summary)),
        ("time_per_phase.png", phase_chart(summary)),
    ):
        path = out_dir / name
        if not cv2.imwrite(str(path), image):
            raise OSError(f"could not write {path}")
        written.append(path)
    return written
