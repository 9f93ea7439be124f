"""Identity readers: the nests, the hotel pockets and the grippers report a plate's id only as far as
their barcode reader read it; presence comes from the sensor, and physics still knows the truth."""

from __future__ import annotations

from lab_description.world import load_world
from labware_model.holders import Nest
from labware_model.readings import NestReading
from tests.helpers.tool_moves import KINEMATICS, move_tool
from tests.tiago_sim.physics.test_sim_pick_place import APPROACH, ARM, CARRY, PLATE, Script
from tiago_sim.physics.identity_readers import IdentityReaders
from tiago_sim.physics.simulation import Simulation


def test_perfect_readers_report_every_plate_and_none_where_there_is_none():
    readers = IdentityReaders()
    assert readers.report("station:a:1", "plate_001") == "plate_001"
    assert readers.report("station:a:1", "") == ""
    assert readers.failed_reads == []


def test_a_failed_read_lasts_until_the_plate_leaves_and_the_next_arrival_reads_again():
    readers = IdentityReaders(failure_rate=1.0, seed=3)
    assert [readers.report("hotel:1", "plate_001") for _ in range(5)] == [""] * 5
    assert readers.failed_reads == [("hotel:1", "plate_001")]  # one read per arrival, not per poll
    readers.report("hotel:1", "")
    readers.report("hotel:1", "plate_001")
    assert readers.failed_reads == [("hotel:1", "plate_001")] * 2


def test_read_outcomes_depend_on_the_seed_not_on_how_often_the_sensors_are_polled():
    holders = [f"station:s:{index}" for index in range(400)]

    def outcomes(polls: int) -> list[str]:
        readers = IdentityReaders(failure_rate=0.2, seed=42)
        result = []
        for holder in holders:
            for _ in range(polls):
                seen = readers.report(holder, "plate_001")
            result.append(seen)
        return result

    once, often = outcomes(1), outcomes(7)
    assert once == often
    failed = once.count("")
    assert 50 < failed < 110  # about 20 % of 400
    other_seed = IdentityReaders(failure_rate=0.2, seed=43)
    assert [other_seed.report(holder, "plate_001") for holder in holders] != once


def test_unread_plates_are_present_without_an_id_and_physics_still_locates_them():
    sim = Simulation(load_world(), seed=11)
    sim.plate_sensing.readers = IdentityReaders(failure_rate=1.0, seed=1)
    script = Script(sim)
    try:
        assert NestReading(Nest("station_a", 1), True, "") in sim.nest_readings()  # seen, not read
        assert sim.check_placement(PLATE, Nest("station_a", 1)).in_nest  # the truth is unchanged
        script.run(sim.undock(), "undock")
        script.drive("station_a_work")
        T_base_site = script.site_in_base("station_a", 1)
        script.run(move_tool(sim, ARM, script.grasp(T_base_site, APPROACH), straight_line=False), "approach")
        script.run(move_tool(sim, ARM, script.grasp(T_base_site)), "descend")
        assert script.run(sim.gripper(ARM, close=True), "close").holding
        script.run(move_tool(sim, ARM, script.grasp(T_base_site, CARRY)), "lift")
        assert sim.grippers[ARM].attached_id == PLATE
        assert sim.held_labware(ARM) == ""  # the gripper's reader failed too
        assert sim.gripper_holds(ARM)  # but the fingers know they hold something
        T_base_slot = KINEMATICS.forward(sim.joint_positions(), "hotel_slot_1")
        script.place(T_base_slot)
        assert [reading.labware_id for reading in sim.hotel_readings()] == ["", ""]
        assert [reading.occupied for reading in sim.hotel_readings()] == [True, False]  # presence
        assert sim.check_placement(PLATE).location.index == 1  # type: ignore[union-attr]
    finally:
        sim.close()
