"""The robot as described: PAL TIAGo++ dimensions, joints, frames and named motions.

Shared by the simulator (which builds its body from it) and the skills (which plan with its
kinematics), as a robot's description package is shared by the robot and its simulation.
- `robot_model`: links, joints and limits (a URDF from primitive shapes, `urdf_writer`),
  with the onboard plate hotel (`hotel_model`);
- `kinematics`: forward and inverse kinematics on that model (pinocchio);
- `motion_library` and `motions.yaml`: the named keyframe motions and the hotel's grasp geometry;
- `transforms`: 4x4 rigid transforms and planar poses.
"""
