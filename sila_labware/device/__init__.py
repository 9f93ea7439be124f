"""The devices' behaviour behind their SiLA features, free of sila2 and of ROS messages.

Protocol order (`sequences`), parameter checks (`validation`), where each plate is (`inventory`),
and the robot and station controllers, typed against the back-end protocols of `robot_backend`
(the ROS bridge's RobotLink in a deployment, an in-memory fake in the fast tests). The SiLA
feature implementations translate the errors of `errors` into SiLA errors.
"""
