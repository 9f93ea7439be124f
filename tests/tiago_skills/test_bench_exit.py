"""The arm leaves a bench by a way clear of the plate it has just placed.

Random layout 208108 (campaign seed 208000 at 7a12b32): after the place into the dispenser's nest 1,
0.89 m high, the straight line back to the bench's front line found no IK on its way (the wrist turns
over near the body), and the one unchecked joint-space move that replaced it swept a finger through
the plate: pushed 3.1 mm, out of its nest (PLACE_FAILED). The way back is now planned as the way in
is, clear of the station's board, bench and nests' labware (tiago_skills.bench_exit).

The fixture is that layout; the replay draws the same disturbances. The whole chain runs as a user
runs it (bench over SiLA, the bridge, ROS, the skills, PyBullet).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from tests.sila_labware.benchmarks.test_bench import run_bench

FIXTURE = Path(__file__).parent / "fixtures" / "placed_plate_below_a_wrist_turn.yaml"
WAY_BACK = re.compile(r"tiago_skills\.bench_route: (?P<way>[\w -]+) to \[[^]]*\] \((?P<nearest>[^)]*)\)")


def test_the_way_back_from_a_placed_plate_passes_clear_of_it(tmp_path: Path) -> None:
    logs = tmp_path / "logs"
    replay = ("--replay", "208108", "--json", "--log-dir", str(logs), "--verbose")
    done = run_bench("--world", str(FIXTURE), *replay)
    assert (logs / "sim_node.log").exists(), f"the robot side did not start:\n{done.stderr[-3000:]}"
    skills_log = (logs / "sim_node.log").read_text()
    after = skills_log.split("no straight way back from over the bench", 1)
    assert len(after) == 2, "the straight line back was found: the fixture lost its point"
    way = WAY_BACK.search(after[1])
    assert way, "no planned way back was logged"
    assert "joint-space move: " in after[1].splitlines()[1], "the unchecked move was not refused by the check"
    assert "plate pushed" not in skills_log
    outcome = json.loads(done.stdout)["outcomes"][0]
    assert outcome["success"], outcome
