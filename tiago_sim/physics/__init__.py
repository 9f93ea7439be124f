"""The PyBullet world: the lab scene, the robot's body and controllers, motions, the success check.

Everything here lives on the one thread that owns the PyBullet client; nothing imports ROS.
"""
