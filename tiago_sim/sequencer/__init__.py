"""The task level a real TIAGo++ keeps: GetLabware and PutLabware as plans of robot actions.

A ROS 2 client of the robot-level actions; imports nothing of the simulation. Run it with
`python -m tiago_sim.sequencer` (see `node`).
"""
