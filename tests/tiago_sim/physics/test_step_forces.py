"""Force limits stay in newtons when the physics step changes (tiago_sim.physics.step_forces).

Why a test: PyBullet keeps a force limit as force times the step current when it was set. Before
the limits were set again at each change of step, both tucked elbows sank 0.42 rad onto their limit
whenever the base drove at 1/30 s, and an attach held an eighth of its load.
"""

from __future__ import annotations

import pybullet as p

from lab_description.world import load_world
from tiago_sim.physics.simulation import DRIVE_STEP_RATIO, START_ARM, Simulation
from tiago_sim.physics.step_forces import StepForces

ELBOWS = ("arm_left_4_joint", "arm_right_4_joint")


def test_the_tucked_arms_hold_their_posture_while_the_base_drives_at_the_long_step() -> None:
    sim = Simulation(load_world(), seed=2)
    try:
        worst = 0.0

        def elbow_error() -> float:
            joints = sim.robot.joint_positions()
            return max(abs(joints[name] - START_ARM[3]) for name in ELBOWS)

        undock = sim.undock()
        while not undock.done:
            sim.step()
            worst = max(worst, elbow_error())
        assert undock.success, undock.message
        drive = sim.command_velocity(0.5, 0.0, 2.0)
        steps = set()
        while not drive.done:
            sim.step()
            steps.add(sim.last_step_s)
            worst = max(worst, elbow_error())
        assert steps == {sim.time_step * DRIVE_STEP_RATIO}  # the long step was the one tried
        assert worst < 0.01, f"an elbow sank {worst:.3f} rad while the base drove"
    finally:
        sim.close()


def test_a_constraint_set_at_a_short_step_holds_its_force_at_a_long_one() -> None:
    client = p.connect(p.DIRECT)
    try:
        p.setGravity(0, 0, -9.81, physicsClientId=client)
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.05] * 3, physicsClientId=client)
        box = p.createMultiBody(1.0, shape, basePosition=[0, 0, 1], physicsClientId=client)
        p.setPhysicsEngineParameter(fixedTimeStep=1 / 240, physicsClientId=client)
        held = p.createConstraint(
            box, -1, -1, -1, p.JOINT_FIXED, [0, 0, 0], [0, 0, 0], [0, 0, 1], physicsClientId=client
        )
        forces = StepForces(client)
        forces.constraint(held, maxForce=12.0)  # 1.2 times the box's weight
        p.setPhysicsEngineParameter(fixedTimeStep=1 / 30, physicsClientId=client)
        forces.restate()
        for _ in range(60):
            p.stepSimulation(physicsClientId=client)
        height = p.getBasePositionAndOrientation(box, physicsClientId=client)[0][2]
        assert abs(height - 1.0) < 0.01, f"the box fell to {height:.2f} m: the limit was not restated"
    finally:
        p.disconnect(client)
