"""Head-camera perception for the simulated TIAGo++: marker assets, RGB-D rendering, ArUco poses.

The perception path works only on rendered pixels; it never reads poses from the simulator.
"""
