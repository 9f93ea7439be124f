"""The robot's skills: the software a TIAGo++ runs to move labware, seeing the robot only
through the hardware port (``robot_port``).

- `perception`: ArUco markers and the held plate in head-camera images (OpenCV);
- `tool_path`: straight tool lines as joint waypoints, by inverse kinematics;
- `goal_run`: one action goal's feedback, cancel and waiting on the hardware;
- `behaviours`, `marker_motion`, `base_alignment`, `place_correction`: what the goals do;
- `action_servers`, `skills_node`: the ROS 2 action servers the task sequencer calls.

The robot model and its kinematics come from `tiago_description`, the lab from `lab_description`.
Nothing here imports PyBullet or the simulator (tests/test_architecture.py holds it).
"""
