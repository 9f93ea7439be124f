"""The plate is found in its nest before a pick, and the fingers go to it, not to the nest believed.

Random layout 202052 (campaign seed 202000 at e724869): the sixth nest of the reader's row lies 1.06 m
from its marker, and the trial's drawn turn of the row (0.63 deg) puts it 7.5 mm across from where
the marker says. The open fingers leave 2.3 mm a side on the plate's short side: they closed on its
edge, pinched it against the nest, and it slipped out of the grip on the way to the hotel
(PLATE_SLIPPED). The skills now read the plate's pose in the nest from the depth image at the working
pose (the head aimed at the nest, which lies out of the marker's view) and grasp it there.

The fixture is that layout; the replay draws the same disturbances. The whole chain runs as a user
runs it (bench over SiLA, the bridge, ROS, the skills, PyBullet).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from tests.sila_labware.benchmarks.test_bench import run_bench

FIXTURES = Path(__file__).parent / "fixtures"
FOUND = re.compile(r"nest 6 of reader: plate at \((-?[\d.]+), (-?[\d.]+)\) mm")


def test_a_plate_far_from_its_marker_is_grasped_where_it_lies(tmp_path: Path) -> None:
    logs = tmp_path / "logs"
    world = str(FIXTURES / "far_nest_of_a_long_row.yaml")
    done = run_bench("--world", world, "--replay", "202052", "--json", "--log-dir", str(logs), "--verbose")
    skills_log = (logs / "sim_node.log").read_text()
    found = FOUND.search(skills_log)
    assert found, "the plate in reader/6 was not located before the pick"
    across_mm = float(found.group(2))
    assert 4.0 < abs(across_mm) < 11.0, f"the fixture lost its point: the plate read {across_mm} mm across"
    outcome = json.loads(done.stdout)["outcomes"][0]
    assert outcome["success"], outcome
