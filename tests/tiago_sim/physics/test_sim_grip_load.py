"""The travel attach and the hotel clamp hold a plate only while friction could.

A constraint fixes a grasped plate to the palm (and a stowed one to the tray) for travel; these
tests show that it lets go when the grip's friction could not hold the load: a weak grip under
the plate's own weight, a plate pressed into the nest, a plate in the hotel something falls on.
The judge is the plate's physical pose, read from PyBullet.
"""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest

from lab_description.world import load_world
from labware_model.holders import GRIPPER, HotelSlot, Nest
from tests.helpers.sim_steps import step_for
from tests.helpers.tool_moves import KINEMATICS, move_tool
from tests.tiago_sim.physics.test_sim_pick_place import APPROACH, ARM, CARRY, PLATE, Script
from tiago_sim.physics.grip_load import GripLoadMonitor
from tiago_sim.physics.simulation import Simulation


def _grasp_at_station_a(grip_force_n: float) -> tuple[Simulation, Script, np.ndarray]:
    sim = Simulation(load_world(), seed=11)
    sim.grippers[ARM].grip_force_n = grip_force_n
    script = Script(sim)
    script.run(sim.undock(), "undock")
    script.drive("station_a_work")
    T_base_site = script.site_in_base("station_a", 1)
    script.run(move_tool(sim, ARM, script.grasp(T_base_site, APPROACH), straight_line=False), "approach")
    script.run(move_tool(sim, ARM, script.grasp(T_base_site)), "descend")
    closed = script.run(sim.gripper(ARM, close=True), "close")
    assert closed.holding  # friction holds the plate on the nest floor, whatever the force
    return sim, script, T_base_site


def test_the_grip_capacity_is_what_the_simulated_friction_contacts_hold():
    """2 mu F_N in the pad plane, 2 F_N s about the closing axis, from PyBullet's combination rules."""
    sim, _script, _site = _grasp_at_station_a(16.0)
    try:
        gripper = sim.grippers[ARM]
        monitor = GripLoadMonitor(
            sim.client_id, sim.robot.id, sim.scene.plates[PLATE], gripper.finger_links, 16.0
        )
        assert monitor.in_plane_capacity_n == pytest.approx(2 * 1.0 * 1.0 * 16.0)  # pad 1.0 x plate 1.0
        assert monitor.twist_capacity_nm == pytest.approx(2 * (0.02 * 1.0 + 0.02 * 1.0) * 16.0)
    finally:
        sim.close()


def test_a_weak_grip_lets_the_plate_slip_out_under_its_weight():
    """1.5 N per finger holds 3 N by friction: less than the 3.4 N a 0.35 kg plate weighs."""
    sim, script, T_base_site = _grasp_at_station_a(1.5)
    try:
        gripper = sim.grippers[ARM]
        lift = sim.run(move_tool(sim, ARM, script.grasp(T_base_site, CARRY)))
        assert lift.success, lift.message
        step_for(sim, 1.0)
        assert gripper.slipped_id == PLATE and gripper.attached_id == ""
        assert gripper.last_slip is not None and not gripper.last_slip.holds
        assert sim.held_labware(ARM) == ""  # the gripper's sensors report it gone
        location = sim.check_placement(PLATE).location
        assert location != GRIPPER, location  # it fell back into the nest or off it
        plate_z = sim.plate_bottom_pose(PLATE)[2, 3]
        tool_z = (sim.robot.base_pose() @ script.grasp(T_base_site, CARRY))[2, 3]
        assert tool_z - plate_z > CARRY - 0.02, "the plate went up with the tool"
    finally:
        sim.close()


def test_at_the_real_force_the_plate_rides_through_lift_and_carry():
    sim, script, T_base_site = _grasp_at_station_a(16.0)
    try:
        gripper = sim.grippers[ARM]
        script.run(move_tool(sim, ARM, script.grasp(T_base_site, CARRY)), "lift")
        T_base_slot = KINEMATICS.forward(sim.joint_positions(), "hotel_slot_1")
        script.run(move_tool(sim, ARM, script.grasp(T_base_slot, CARRY)), "carry to the hotel")
        assert gripper.slipped_id == "" and gripper.attached_id == PLATE
        assert sim.check_placement(PLATE).location == GRIPPER
    finally:
        sim.close()


def test_a_plate_pressed_into_the_nest_slips_in_the_fingers():
    """The tool goes 8 mm below where the plate rests: the nest floor pushes back harder than the
    pads' friction holds, the attach lets go and the plate stays on the floor."""
    sim, script, T_base_site = _grasp_at_station_a(16.0)
    try:
        gripper = sim.grippers[ARM]
        script.run(move_tool(sim, ARM, script.grasp(T_base_site, 0.02)), "lift a little")
        assert gripper.attached_id == PLATE
        sim.run(move_tool(sim, ARM, script.grasp(T_base_site, -0.008), tool_speed=0.02))
        assert gripper.slipped_id == PLATE, "the attach held a plate pressed into the nest floor"
        assert gripper.last_slip is not None
        assert gripper.last_slip.largest_push[2] > 0.0  # the load came from a contact, not from inertia
        check = sim.check_placement(PLATE, Nest("station_a", 1))
        assert check.in_nest, check
    finally:
        sim.close()


def test_the_hotel_clamp_opens_on_a_plate_something_falls_on():
    sim = Simulation(load_world(), seed=11)
    script = Script(sim)
    try:
        script.run(sim.undock(), "undock")
        script.drive("station_a_work")
        script.pick(script.site_in_base("station_a", 1))
        T_base_slot = KINEMATICS.forward(sim.joint_positions(), "hotel_slot_1")
        script.place(T_base_slot)
        assert sim.check_placement(PLATE).location == HotelSlot(1)
        drive = sim.drive_to(*sim.odometry()[:2], sim.odometry()[2] + 1.0)  # turn on the spot
        step_for(sim, 0.3)
        assert PLATE in sim.hotel_clamp.constraints, "the clamp did not close for the drive"
        above = sim.robot.link_pose("hotel_slot_1") @ np.array([0.0, 0.0, 0.06, 1.0])
        box = p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.02] * 3, physicsClientId=sim.client_id)
        p.createMultiBody(0.5, box, -1, above[:3].tolist(), physicsClientId=sim.client_id)
        step_for(sim, 0.5)
        assert PLATE not in sim.hotel_clamp.constraints, "the clamp held against the falling box"
        sim.run(drive)
    finally:
        sim.close()


def test_the_step_where_the_physics_step_changes_length_counts_no_acceleration():
    """A velocity jump on the first step of another length is the position control's discretisation
    (it corrects a tracking error faster at the shorter step), not a load; the next one counts."""
    sim, _script, _site = _grasp_at_station_a(16.0)
    try:
        client, plate = sim.client_id, sim.scene.plates[PLATE]
        monitor = GripLoadMonitor(client, sim.robot.id, plate, sim.grippers[ARM].finger_links, 16.0)
        grasp = sim.robot.link_pose(f"gripper_{ARM}_grasping_frame")
        along = grasp[:3, 0]  # in the pad plane
        p.resetBaseVelocity(plate, [0.0, 0.0, 0.0], physicsClientId=client)
        monitor.load(1 / 60, grasp)
        still = monitor.load(1 / 60, grasp)  # weight and the nest's push only
        p.resetBaseVelocity(plate, (0.2 * along).tolist(), physicsClientId=client)  # 48 m/s^2 at 1/240 s
        switched = monitor.load(1 / 240, grasp)
        p.resetBaseVelocity(plate, (0.4 * along).tolist(), physicsClientId=client)
        after = monitor.load(1 / 240, grasp)
    finally:
        sim.close()
    assert switched.in_plane_n == pytest.approx(still.in_plane_n, abs=1e-6)
    assert after.in_plane_n > still.in_plane_n + 10.0  # 0.35 kg x 48 m/s^2 = 16.8 N
