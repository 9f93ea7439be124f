"""The head camera's perception: ArUco markers, the nest frames they imply, the plate in the hand.

Works only on camera pixels, depth and the robot model; it never reads poses from the simulator.
"""
