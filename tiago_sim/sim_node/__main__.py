"""`python -m tiago_sim.sim_node`: the simulated TIAGo++ as a ROS 2 node."""

from tiago_sim.sim_node.node import main

if __name__ == "__main__":
    raise SystemExit(main())
