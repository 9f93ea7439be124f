"""After a release near the top of the arm's reach, the empty gripper rises straight up the column
in the twin it is in, to a lower approach if the higher one has no straight line.

Random layout 219071 (campaign seed 219000 at a668344): the plate rested in sealer/1 (0.88 m high),
but the rise to 80 mm over it was planned for the other twin, whose line turned the wrist half round
and passed a flip the arm could not follow (IK_FAILED, LabwareNotPlaced). The fixture is that layout;
the replay draws the same disturbances; the whole chain runs as a user runs it.
"""

from __future__ import annotations

import json
from pathlib import Path

from tests.sila_labware.benchmarks.test_bench import run_bench

FIXTURE = Path(__file__).parent / "fixtures" / "retreat_after_a_release_at_the_reach_top.yaml"


def test_the_gripper_rises_off_a_high_nest_after_the_release_and_the_plate_is_delivered(
    tmp_path: Path,
) -> None:
    done = run_bench("--world", str(FIXTURE), "--replay", "219071", "--json")
    outcome = json.loads(done.stdout)["outcomes"][0]
    assert outcome["success"], outcome  # IK_FAILED on the rise after the release without the fix
