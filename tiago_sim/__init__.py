"""The robot side: a simulated PAL TIAGo++ in a lab described by a world file.

Subpackages, lowest first (each imports only those before it):
- `lab`: the world file as frozen data (stations, nests, markers, POIs, plates); no PyBullet;
- `robot`: the robot model (URDF from primitive shapes), its kinematics and named motions;
- `physics`: the PyBullet world and robot: scene, controllers, motions, the success check;
- `perception`: ArUco markers in rendered camera images, with OpenCV;
- `measuring`: disturbances, fault injection, the run recorder and the ROS benchmark;
- `sim_node`: the ROS 2 node that owns the simulation (action servers, publishers, skills);
- `sequencer`: the task level a real TIAGo++ keeps (GetLabware, PutLabware): a ROS client of the
  robot-level actions that imports nothing of the simulation.
`transforms` (4x4 rigid transforms) and `node_main` (the shared rclpy main loop) serve them all.
Below them all lies `labware_model` (a package of its own, shared with the SiLA side): labware
types, plates, nests and hotel slots are named there.
"""
