"""The digital twin's start-up: the simulated TIAGo++ (tiago_sim) and the robot's skills
(tiago_skills) in one process, joined through the hardware port (robot_port).

The only package that imports both sides (tests/test_architecture.py holds it). Run it with
`python -m tiago_twin --world FILE` (see `startup`); `lab_reset` serves /reset_lab, which rebuilds
the simulated lab and makes the skills forget what they remembered of the old one.
"""
