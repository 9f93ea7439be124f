"""bluesky-queueserver startup code: `start-re-manager --startup-dir` this folder (see
ros_bridge/bluesky/queueserver.py). The worker runs it when its environment opens; what it
defines is what users may queue: the plans below, with the devices `robot`, `stage` and
`detector` as arguments, on the RunEngine `RE`."""

import os

from bluesky.plans import count  # noqa: F401 - a measurement between robot tasks queued apart

from ros_bridge.bluesky.queueserver import queue_plans, start_profile

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")  # as the robot side's nodes

robot_task_plan, sample_exchange_plan = queue_plans()
RE, robot, stage, detector = start_profile()
