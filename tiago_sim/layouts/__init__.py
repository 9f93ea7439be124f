"""Random labs for campaigns over layouts the robot was never tuned on (README "Random layouts")."""
