"""Scripted pick and place in physics: station A nest -> hotel slot 1 -> station B nest.

The targets come from known frames (world ground truth for the site, FK for the hotel slot): this
test proves the physics of grasp, carry and release; the real run finds the site by perception.
The judge is the plate's physical pose, read from PyBullet.
"""

from __future__ import annotations

import itertools

import numpy as np
import pybullet as p
import pytest

from lab_description.world import load_world
from labware_model.holders import GRIPPER, HotelSlot, Nest
from labware_model.readings import HotelSlotReading, NestReading
from tests.helpers.sim_steps import step_for, step_lengths
from tests.helpers.tool_moves import KINEMATICS, TOOL_SPEED, move_tool
from tiago_description import robot_model as rm
from tiago_description import transforms as tf
from tiago_description.kinematics import top_down_grasp
from tiago_sim.physics.plate_proximity import CONTACT_MARGIN, STEP_REVIEW_PERIOD
from tiago_sim.physics.simulation import FREE_MOTION_STEP_RATIO, START_ARM, Simulation

ARM = "right"
APPROACH = 0.10
CARRY = 0.15
PLATE = "plate_001"


class Script:
    """Small helpers around one Simulation: every step must succeed."""

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        self.plate_height = sim.world.labware_types["sbs_microplate_96"].height
        self.slips_m: list[float] = []

    def run(self, motion, what: str):
        self.sim.run(motion, timeout_s=60.0)
        assert motion.success, f"{what}: {motion.error_code} {motion.message}"
        return motion

    def grasp(self, T_base_site: np.ndarray, lift: float = 0.0) -> np.ndarray:
        position = T_base_site[:3, 3] + [0.0, 0.0, self.plate_height / 2 + lift]
        return top_down_grasp(position, tf.yaw_of(T_base_site))

    def plate_in_base(self) -> np.ndarray:
        return tf.invert(self.sim.robot.base_pose()) @ self.sim.plate_bottom_pose(PLATE)

    def plate_in_grasp(self) -> np.ndarray:
        T_base_grasp = KINEMATICS.forward(self.sim.joint_positions(), f"gripper_{ARM}_grasping_frame")
        return tf.invert(T_base_grasp) @ self.plate_in_base()

    def pick(self, T_base_site: np.ndarray) -> None:
        self.run(move_tool(self.sim, ARM, self.grasp(T_base_site, APPROACH), straight_line=False), "approach")
        self.run(move_tool(self.sim, ARM, self.grasp(T_base_site)), "descend")
        closed = self.run(self.sim.gripper(ARM, close=True), "close")
        assert closed.holding and closed.opening_m == pytest.approx(0.08548, abs=0.002)
        assert self.sim.held_labware(ARM) == PLATE
        before = self.plate_in_base()
        self.run(move_tool(self.sim, ARM, self.grasp(T_base_site, CARRY)), "lift")
        after = self.plate_in_base()
        self.slips_m.append(float(np.linalg.norm(after[:3, 3] - before[:3, 3] - [0, 0, CARRY])))

    def place(self, T_base_site: np.ndarray) -> None:
        T_before = self.plate_in_grasp()
        self.run(move_tool(self.sim, ARM, self.grasp(T_base_site, CARRY)), "carry")
        self.run(move_tool(self.sim, ARM, self.grasp(T_base_site, 0.002)), "lower")
        self.slips_m.append(float(np.linalg.norm(self.plate_in_grasp()[:3, 3] - T_before[:3, 3])))
        opened = self.run(self.sim.gripper(ARM, close=False), "open")
        assert not opened.holding and opened.opening_m > 0.095
        self.run(move_tool(self.sim, ARM, self.grasp(T_base_site, CARRY)), "retreat")
        assert self.sim.held_labware(ARM) == ""

    def drive(self, poi: str) -> None:
        """To a station's working pose (where the marker-guided final approach ends), else to the POI."""
        stations = {station.poi: station for station in self.sim.world.stations}
        goal = stations[poi].aligned_pose() if poi in stations else self.sim.world.pois[poi]
        self.run(self.sim.drive_to(goal.x, goal.y, goal.yaw), f"drive to {poi}")

    def site_in_base(self, station: str, sub: int) -> np.ndarray:
        return tf.invert(self.sim.robot.base_pose()) @ self.sim.world.station(station).T_world_site(sub)


def test_plate_goes_from_station_a_through_the_hotel_to_station_b():
    world = load_world()
    sim = Simulation(world, seed=11)
    script = Script(sim)
    try:
        assert sim.check_placement(PLATE, Nest("station_a", 1)).in_nest
        script.run(sim.undock(), "undock")
        script.drive("station_a_work")
        script.pick(script.site_in_base("station_a", 1))
        assert sim.check_placement(PLATE).location == GRIPPER
        assert sim.nest_readings()[0] == NestReading(Nest("station_a", 1), False, "")

        T_base_slot = KINEMATICS.forward(sim.joint_positions(), "hotel_slot_1")
        script.place(T_base_slot)
        assert sim.hotel_readings() == [
            HotelSlotReading(HotelSlot(1), PLATE, "sbs_microplate_96"),
            HotelSlotReading(HotelSlot(2), "", ""),
        ]
        home = dict(zip(rm.arm_joint_names(ARM), START_ARM, strict=True))
        script.run(sim.move_joints(home), "home")

        script.drive("station_b_work")
        assert sim.check_placement(PLATE).location == HotelSlot(1)  # it rode along in its pocket
        script.pick(T_base_slot)
        script.place(script.site_in_base("station_b", 1))

        check = sim.check_placement(PLATE, Nest("station_b", 1))
        clearance = world.station("station_b").nest_clearance
        assert check.in_nest, check
        assert check.location == Nest("station_b", 1)
        assert check.position_error_m < clearance * 1.5 + 0.001
        assert check.yaw_error_rad < np.radians(1.0)
        assert NestReading(Nest("station_b", 1), True, PLATE) in sim.nest_readings()
        # the plate settles 2 to 3 mm in the pads as the lift starts, by the arm's IK solution
        assert max(script.slips_m) < 0.004, script.slips_m
        # grasps, releases and the hotel's pocket touch the plate, but push it nowhere
        assert sim.plate_pushes.pushes == []
    finally:
        sim.close()


def _tool_above_station_a(height: float) -> tuple[Simulation, Script, np.ndarray]:
    """Driven to station A's working pose, the open tool ``height`` above its plate; the caller closes
    the simulation."""
    sim = Simulation(load_world(), seed=11)
    script = Script(sim)
    try:
        script.run(sim.undock(), "undock")
        script.drive("station_a_work")
        T_base_site = script.site_in_base("station_a", 1)
        script.run(move_tool(sim, ARM, script.grasp(T_base_site, height), straight_line=False), "approach")
    except BaseException:
        sim.close()
        raise
    return sim, script, T_base_site


def test_a_held_plate_takes_long_steps_in_free_space_and_short_ones_near_the_table():
    """The long step is where the simulation wins its speed; a held plate gets it only out of reach."""
    sim, script, T_base_site = _tool_above_station_a(APPROACH)
    try:
        script.run(move_tool(sim, ARM, script.grasp(T_base_site)), "descend")
        script.run(sim.gripper(ARM, close=True), "close")
        long_step = sim.time_step * FREE_MOTION_STEP_RATIO
        lift = move_tool(sim, ARM, script.grasp(T_base_site, CARRY))
        up = step_lengths(sim, lift)
        assert lift.success, lift
        assert up[:20] == [sim.time_step] * 20 and up[-1] == long_step, up
        lower = move_tool(sim, ARM, script.grasp(T_base_site, 0.002))
        down = step_lengths(sim, lower)
        assert lower.success, lower
        assert down[0] == long_step and down[-20:] == [sim.time_step] * 20, down
        assert sim.check_placement(PLATE).location == GRIPPER
    finally:
        sim.close()


def _gap_to_plate(sim: Simulation) -> float:
    """The nearest robot link (not the base) to the plate, in m (0.3 when none is within 0.3 m)."""
    points = p.getClosestPoints(sim.robot.id, sim.scene.plates[PLATE], 0.3, physicsClientId=sim.client_id)
    return min((point[8] for point in points if point[3] != -1), default=0.3)


def test_a_descent_onto_a_resting_plate_takes_short_steps_only_within_reach_of_it():
    """Long steps while the tool is further than it can travel before the next review (plus the
    margin), short ones from there on: the contact physics never starts on a long step."""
    sim, script, T_base_site = _tool_above_station_a(CARRY)
    try:
        descent = move_tool(sim, ARM, script.grasp(T_base_site))
        steps = []
        while not descent.done:
            gap = _gap_to_plate(sim)
            sim.step()
            steps.append((gap, sim.last_step_s))
        assert descent.success, descent
    finally:
        sim.close()
    long_step = sim.time_step * FREE_MOTION_STEP_RATIO
    reach = CONTACT_MARGIN + 2 * TOOL_SPEED * STEP_REVIEW_PERIOD
    assert all(step == sim.time_step for gap, step in steps if gap < CONTACT_MARGIN)
    far = [step for gap, step in steps if gap > reach + TOOL_SPEED * STEP_REVIEW_PERIOD]
    assert len(far) > 20 and set(far) == {long_step}  # before: short from 0.15 m on


def test_closing_on_nothing_reports_not_holding():
    sim = Simulation(load_world(), seed=2)
    try:
        motion = sim.run(sim.gripper(ARM, close=True))
        assert motion.success and not motion.holding
        assert motion.opening_m == pytest.approx(2 * rm.FINGER_MOUNT_OFFSET, abs=0.001)
        busy = sim.gripper(ARM, close=False)
        sim.run(busy)
        assert sim.grippers[ARM].opening() == pytest.approx(0.1, abs=0.001)
    finally:
        sim.close()


def test_nest_lead_ins_guide_a_plate_released_off_centre():
    """Perception and odometry leave millimetres of error: the chamfered nest must absorb them."""
    world = load_world()
    sim = Simulation(world, seed=5)
    script = Script(sim)
    try:
        script.run(sim.undock(), "undock")
        script.drive("station_a_work")
        script.pick(script.site_in_base("station_a", 1))
        error = tf.from_xyz_rpy((-0.004, 0.003, 0.0), (0.0, 0.0, np.radians(1.5)))
        script.place(script.site_in_base("station_a", 2) @ error)
        check = sim.check_placement(PLATE, Nest("station_a", 2))
        assert check.in_nest, check
        assert check.position_error_m < 0.0025
    finally:
        sim.close()


def _rest_plate_on_pocket_edge(sim: Simulation, side: int, outwards: float, yaw: float) -> None:
    """Set PLATE into station_a nest 2 tilted across the nest, one long bottom edge 1.5 mm up.

    The raised edge is ``outwards`` beyond the pocket edge on the ``side`` (+1 or -1) long side:
    where a plate sliding down a lead-in arrives, and where the former 1.5 mm bracket wall left
    campaign plates resting 1 deg tilted.
    """
    site = sim.world.station("station_a")
    plate = sim.world.labware_types["sbs_microplate_96"]
    raised = 0.0015
    tilt = side * np.arcsin(raised / plate.width)
    edge_y = side * (plate.width / 2 + site.nest_clearance + outwards)
    T_site_bottom = tf.from_xyz_rpy(
        (0.0, edge_y - side * plate.width / 2 * np.cos(tilt), raised / 2 + 0.0002), (tilt, 0.0, yaw)
    )
    T_world_centre = site.T_world_site(2) @ T_site_bottom @ tf.make_transform((0, 0, plate.height / 2))
    position, quat = tf.to_pose(T_world_centre)
    body = sim.scene.plates[PLATE]
    p.resetBasePositionAndOrientation(body, position.tolist(), quat.tolist(), physicsClientId=sim.client_id)
    p.resetBaseVelocity(body, [0, 0, 0], [0, 0, 0], physicsClientId=sim.client_id)


def test_a_plate_arriving_at_the_pocket_edge_settles_flat_in_the_nest():
    """No ledge at the foot of a lead-in: the plate's bottom must not come to rest on a bracket."""
    sim = Simulation(load_world(), seed=3)
    try:
        refused = []
        for side in (1, -1):
            for outwards_mm, yaw_deg in itertools.product(np.arange(-0.4, 1.65, 0.1), (0.0, 0.3)):
                _rest_plate_on_pocket_edge(sim, side, outwards_mm / 1000, np.radians(yaw_deg))
                step_for(sim, 2.0)
                check = sim.check_placement(PLATE, Nest("station_a", 2))
                if not check.in_nest:
                    where = f"side {side:+d}, {outwards_mm:.1f} mm out, yaw {yaw_deg} deg"
                    refused.append(f"{where}: {check.outside}")
        assert not refused, refused
    finally:
        sim.close()


def test_grasp_holds_a_plate_when_the_gripper_arrives_off_centre():
    """Both pads must reach the plate even when the tool is millimetres and a degree or two off."""
    world = load_world()
    sim = Simulation(world, seed=9)
    script = Script(sim)
    try:
        script.run(sim.undock(), "undock")
        script.drive("station_a_work")
        error = tf.from_xyz_rpy((0.002, -0.003, 0.0), (0.0, 0.0, np.radians(1.5)))
        T_base_site = script.site_in_base("station_a", 1) @ error
        script.run(move_tool(sim, ARM, script.grasp(T_base_site, APPROACH), straight_line=False), "approach")
        script.run(move_tool(sim, ARM, script.grasp(T_base_site)), "descend")
        closed = script.run(sim.gripper(ARM, close=True), "close")
        assert closed.holding and 0.085 < closed.opening_m < 0.090
        before = script.plate_in_grasp()
        script.run(move_tool(sim, ARM, script.grasp(T_base_site, CARRY)), "lift")
        assert sim.held_labware(ARM) == PLATE
        assert sim.check_placement(PLATE).location == GRIPPER
        assert np.linalg.norm(script.plate_in_grasp()[:3, 3] - before[:3, 3]) < 0.002
    finally:
        sim.close()


def _drop_plate_over_nest(sim: Simulation, along_mm: float) -> None:
    """Let PLATE fall from the release height (6 mm) over station_a nest 2, `along_mm` off lengthwise."""
    site = sim.world.station("station_a")
    plate = sim.world.labware_types["sbs_microplate_96"]
    T_site_centre = tf.make_transform((along_mm / 1000, 0.0, 0.006 + plate.height / 2))
    position, quat = tf.to_pose(site.T_world_site(2) @ T_site_centre)
    body = sim.scene.plates[PLATE]
    p.resetBasePositionAndOrientation(body, position.tolist(), quat.tolist(), physicsClientId=sim.client_id)
    p.resetBaseVelocity(body, [0, 0, 0], [0, 0, 0], physicsClientId=sim.client_id)
    step_for(sim, 2.0)


def test_the_nest_sensor_sees_a_seated_plate_and_not_one_on_a_lead_in_rim():
    """A plate released 9 mm off rests on the rim of a lead-in, 3 mm up (the 200 trials at 7b59091
    failed only so, each reported delivered by the robot); the pocket floor's sensor must not see it,
    so the robot reports it as not placed. One released 3 mm off slides in and is seen."""
    sim = Simulation(load_world(), seed=3)
    nest = Nest("station_a", 2)
    try:
        _drop_plate_over_nest(sim, 3.0)
        assert sim.check_placement(PLATE, nest).in_nest
        assert NestReading(nest, True, PLATE) in sim.nest_readings()
        _drop_plate_over_nest(sim, 9.5)
        check = sim.check_placement(PLATE, nest)
        assert not check.in_nest and "raised" in check.outside, check
        assert NestReading(nest, False, "") in sim.nest_readings()
    finally:
        sim.close()


def _planar_in(T_reference: np.ndarray, T: np.ndarray) -> np.ndarray:
    """(x, y in mm, yaw in deg) of ``T`` in the frame ``T_reference``."""
    relative = tf.invert(T_reference) @ T
    return np.array([*(1000 * relative[:2, 3]), np.degrees(tf.yaw_of(relative))])


def test_a_held_plate_stays_where_the_hand_holds_it_and_is_let_go_of_where_it_hangs():
    """The place correction measures the held plate above the nest and moves the tool by what it
    sees, so the plate must not move in the hand after that nor at the release. Read from the
    physics in test_examples: with the full grip force squeezing against the travel attach, and the
    attach let go of while the pads still squeezed, the plate moved by up to 1 mm and 0.7 deg in the
    hand between the measurement and the release and up to 1.2 mm more as the pads opened. What is
    left: as the physics step shortens near the nest the hold settles by about 0.2 mm (the step sets
    how far a constraint yields under its load), hence 0.3 mm in the hand."""
    sim, script, T_base_site = _tool_above_station_a(APPROACH)
    try:
        script.run(move_tool(sim, ARM, script.grasp(T_base_site)), "descend")
        script.run(sim.gripper(ARM, close=True), "close")
        script.run(move_tool(sim, ARM, script.grasp(T_base_site, CARRY)), "lift")
        script.run(move_tool(sim, ARM, script.grasp(T_base_site, APPROACH)), "over the nest")
        measured = script.plate_in_grasp()  # where the measurement would see it
        script.run(move_tool(sim, ARM, script.grasp(T_base_site, 0.006)), "lower")
        lowered = script.plate_in_grasp()
        hanging = sim.plate_bottom_pose(PLATE)
        opening = sim.gripper(ARM, close=False)
        while not sim.grippers[ARM].pads_clear_of(PLATE):  # until the pads have left the plate
            assert not opening.done, "the fingers opened fully without leaving the plate"
            sim.step()
        let_go = _planar_in(hanging, sim.plate_bottom_pose(PLATE))
        moved_in_hand = _planar_in(measured, lowered)
        assert np.all(np.abs(moved_in_hand[:2]) < 0.3) and abs(moved_in_hand[2]) < 0.2, moved_in_hand
        assert np.all(np.abs(let_go[:2]) < 0.2) and abs(let_go[2]) < 0.1, let_go
        script.run(opening, "open")
    finally:
        sim.close()
