"""The simulated PAL TIAGo++ in a lab a world file describes: the robot's hardware and the
vendor's stack, played in PyBullet, and the task level a real TIAGo++ keeps.

Subpackages, lowest first (each imports only those before it, and the descriptions and the
hardware port below them all):
- `navigation`: the occupancy map, the planner, scan matching and localisation (plain geometry);
- `inspection`, `layouts`: `world check`, random labs and obstacles for campaigns;
- `physics`: the PyBullet world and robot: scene, controllers, motions, sensors, camera
  rendering, the success check;
- `measuring`: disturbances, fault injection, the run recorder and the ROS benchmark;
- `sim_node`: the simulator's ROS side: the sim thread, the hardware port on it
  (`sim_node.hardware`), sensor topics, the navigation stand-in, faults, ground truth;
- `sequencer`: the task level (GetLabware, PutLabware): a ROS client of the robot-level actions
  that imports nothing of the simulation.
`node_main` (the shared rclpy main loop) serves the two processes. The robot's skills are not
here (`tiago_skills`, behind `robot_port`); `tiago_twin` starts them with the simulator. Below
them all lie `tiago_description` (the robot model), `lab_description` (the world file) and
`labware_model` (labware types, plates, nests and hotel slots, shared with the SiLA side).
"""
