"""The ROS 2 node that owns the simulation: action servers, publishers, the robot's skills.

Run it with `python -m tiago_sim.sim_node --world FILE` (see `node`).
"""
