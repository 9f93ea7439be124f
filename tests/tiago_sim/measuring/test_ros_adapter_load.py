"""The adapter-load benchmark finds the message class of every topic the graph reports, an action's
feedback and status included (its run itself is measured on the benchmarks page, not here)."""

from __future__ import annotations

from action_msgs.msg import GoalStatusArray
from control_msgs.action import FollowJointTrajectory
from sensor_msgs.msg import JointState

from tiago_sim.measuring.ros_adapter_load import _message_type


def test_a_topic_type_names_its_message_class() -> None:
    assert _message_type("sensor_msgs/msg/JointState") is JointState
    assert _message_type("action_msgs/msg/GoalStatusArray") is GoalStatusArray
    feedback = _message_type("control_msgs/action/FollowJointTrajectory_FeedbackMessage")
    assert feedback is FollowJointTrajectory.Impl.FeedbackMessage
