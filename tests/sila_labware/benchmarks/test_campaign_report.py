"""The campaign report's charts, drawn from the committed campaign summary (no stack, a second).

The full bench test (test_bench.py) writes them from a real two-trial campaign as well; here the
committed 200-trial summary and an empty campaign (stopped before its first trial) are drawn.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import cv2
import pytest

from sila_labware.benchmarks.campaign import summarize
from sila_labware.benchmarks.campaign_report import phase_chart, success_chart, write_charts

COMMITTED_SUMMARY = Path(__file__).resolve().parent / "fixtures" / "campaign_summary.json"


@pytest.fixture(scope="module")
def summary() -> dict:
    return json.loads(COMMITTED_SUMMARY.read_text())


def test_charts_are_written_as_pngs_with_content(summary: dict, tmp_path: Path) -> None:
    written = write_charts(summary, tmp_path / "report")
    assert [path.name for path in written] == ["success_by_cause.png", "time_per_phase.png"]
    for path in written:
        image = cv2.imread(str(path))
        assert image is not None and image.shape[0] > 300 and image.shape[1] > 1000, path.name
        assert image.std() > 10, f"{path.name} is blank"
        assert (image[0, 0] == 255).all(), f"{path.name}: the background is not white"


def test_charts_say_what_the_summary_says(summary: dict) -> None:
    success = success_chart(summary)
    texts = [success.get_suptitle()] + [axes.get_title(loc="left") for axes in success.axes]
    assert texts == ["200 transfers, 199 delivered (99.5 %), seed 10000", "outcome", "failures by cause"]
    causes = [label.get_text() for label in success.axes[1].get_yticklabels()]
    assert causes == list(summary["failures"])
    assert [bar.get_width() for bar in success.axes[1].patches] == list(summary["failures"].values())

    phases = phase_chart(summary)
    labels = [label.get_text().replace("\n", " ") for label in phases.axes[0].get_yticklabels()]
    assert labels == [*summary["phases"], "whole transfer (delivered)"]
    assert "real-time factor 10.0" in phases.get_suptitle()


def test_an_empty_campaign_still_gets_its_charts(tmp_path: Path) -> None:
    """A campaign interrupted before its first trial has no phases and no trials."""
    empty = summarize([], {}, seed=1)
    for path in write_charts(empty, tmp_path):
        assert cv2.imread(str(path)) is not None, path.name


def test_drawing_charts_leaves_pyplot_alone(summary: dict, tmp_path: Path) -> None:
    """Figures on their own Agg canvas: no pyplot figure is created, the backend is not switched."""
    import matplotlib

    backend = matplotlib.get_backend()
    write_charts(summary, tmp_path)
    assert matplotlib.get_backend() == backend
    pyplot = sys.modules.get("matplotlib.pyplot")
    assert pyplot is None or pyplot.get_fignums() == []
