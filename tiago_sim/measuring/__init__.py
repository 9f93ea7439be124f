"""Measuring tools: seeded disturbances, fault injection, the run recorder, the ROS benchmark."""
