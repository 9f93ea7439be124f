"""A TIAGo++ behind the hardware port (robot_port.RobotHardware), over the robot's own ROS 2 interfaces.

What runs the twin runs the robot: the skills see a robot through the port; this adapter fills it
from the interfaces a TIAGo++ offers (robot_port.tiago_interfaces: its controllers'
FollowJointTrajectory actions, /joint_states, odometry, the base laser, the head camera, the base's
velocity command, Nav2's navigate_to_pose), which the simulator serves too (tiago_twin
--robot-interfaces). Not yet: docking (docs/reference/robot-interfaces.md).
"""
