"""Which plate the demo asks physics about after a transfer (plate_to_judge).

Why: with the source's label unread, the check asked about plate "" and found it nowhere (random
layout 91072 counted a plate seated in labeler/1 as misplaced). A fake link stands in for the bridge.
"""

from __future__ import annotations

from labware_model.holders import Nest
from labware_model.readings import NestReading
from sila_labware.deployment.demo import plate_to_judge

DESTINATION = Nest("labeler", 1)


class FakeLink:
    def __init__(self, *readings: NestReading) -> None:
        self.readings = readings
        self.asked = 0

    def nest_readings(self) -> tuple[NestReading, ...]:
        self.asked += 1
        return self.readings


def test_the_id_read_at_the_source_is_judged() -> None:
    link = FakeLink(NestReading(DESTINATION, True, "plate_009"))
    assert plate_to_judge(link, "plate_002", DESTINATION) == "plate_002"
    assert link.asked == 0


def test_an_unread_source_label_is_judged_by_the_id_read_on_arrival() -> None:
    link = FakeLink(
        NestReading(Nest("labeler", 3), True, "plate_003"), NestReading(DESTINATION, True, "plate_002")
    )
    assert plate_to_judge(link, "", DESTINATION) == "plate_002"


def test_nothing_read_anywhere_leaves_no_id() -> None:
    assert plate_to_judge(FakeLink(NestReading(DESTINATION, True, "")), "", DESTINATION) == ""
    assert plate_to_judge(FakeLink(NestReading(DESTINATION, False, "")), "", DESTINATION) == ""
