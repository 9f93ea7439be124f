"""The TIAGo++ model without a simulator: URDF from primitive shapes, kinematics, named motions."""
