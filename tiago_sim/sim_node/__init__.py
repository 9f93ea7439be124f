"""The simulator's ROS 2 side: the sim thread that owns PyBullet, the hardware port on it
(`hardware`), the sensor topics, the navigation stand-in and localisation, fault injection.

Nothing here is robot software: `python -m tiago_twin --world FILE` starts it with the skills.
"""
