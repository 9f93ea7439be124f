"""A held plate the head does not see whole before a place is looked at again, with the marker.

Random layout 191031 (campaign seed 191000 at 89e359f): above reader/1 the held plate ran out of the
head image's edge at the gaze that had seen the marker, the place correction measured nothing, and
the plate went down uncorrected onto the nest's brackets (PLACE_FAILED). The skills now aim the head
between the marker and the tool, see both again with that one gaze, and place the plate measured.

(What the skills do when a measured place lies beyond the arm's reach: test_reachable.py.)

The fixture is that layout; the replay draws the same disturbances. The whole chain runs as a user
runs it (bench over SiLA, the bridge, ROS, the skills, PyBullet).
"""

from __future__ import annotations

import json
from pathlib import Path

from tests.sila_labware.benchmarks.test_bench import run_bench

FIXTURES = Path(__file__).parent / "fixtures"
LOOKED_AGAIN = "looking again with marker and held plate in one view"
MEASURED = "held plate at ("


def test_a_plate_half_out_of_the_image_is_seen_again_and_placed(tmp_path: Path) -> None:
    logs = tmp_path / "logs"
    world = str(FIXTURES / "plate_beyond_the_image_edge.yaml")
    done = run_bench("--world", world, "--replay", "191031", "--json", "--log-dir", str(logs), "--verbose")
    skills_log = (logs / "sim_node.log").read_text()
    first, _, after = skills_log.partition(LOOKED_AGAIN)
    assert after, "the plate was seen whole at the first gaze: the fixture lost its point"
    assert "held plate not measured: no plate type fits the pixels" in first
    assert MEASURED in after, "the second gaze did not measure the plate"
    outcome = json.loads(done.stdout)["outcomes"][0]
    assert outcome["success"], outcome
