"""The hardware port: everything the robot's skills may ask of a robot, as types and a protocol.

Why a package of its own at the bottom of the tree: the skills (``tiago_skills``) are the software a
real TIAGo++ runs, and the simulator (``tiago_sim``) only plays the robot's hardware and vendor
stack. Both import this package and neither imports the other; the start-up module
(``tiago_twin``) hands the simulator's implementation to the skills. An adapter on a real robot's
ROS 2 interfaces implements the same protocol (``docs/explanation/hardware-port.md``).

- ``types``: what crosses the port (joint trajectories, camera frames, laser scans, poses);
- ``execution``: the handle of something the hardware does over time (a trajectory, a drive);
- ``hardware``: the protocol itself, ``RobotHardware``.
"""
