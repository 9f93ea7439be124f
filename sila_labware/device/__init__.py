"""The devices' behaviour behind their SiLA features, free of sila2 and of ROS messages.

Protocol order (`sequences`), parameter checks (`validation`), where each plate is (`inventory`),
and the robot and station controllers that drive the ROS bridge. The SiLA feature
implementations translate the errors of `errors` into SiLA errors.
"""
