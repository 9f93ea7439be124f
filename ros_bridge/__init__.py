"""The SiLA-ROS bridge: the robot side's ROS 2 actions, services and topics, usable from any thread.

Knows the labware_interfaces contract and nothing of the simulation or of SiLA. One
`runtime.RosRuntime` owns rclpy (one context, node and executor on one thread); `actions`,
`services` and `topics` are thread-safe callers on top of it; `robot_link.RobotLink` names the
robot's interfaces and returns plain values: the snapshots of `workcell` and the nests, readings
and workcell description of `labware_model`. A sent goal is a `goal_status.ActionGoal`, the one
status contract its callers use; `progress` holds the rule that progress never goes down.
"""
