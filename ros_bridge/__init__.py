"""ros_bridge package."""
