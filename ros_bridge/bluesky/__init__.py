"""Bluesky front door: the labware robot as an Ophyd device, driven by RunEngine plans.

Importable without sila2: only ophyd, bluesky and the ROS bridge below it. Storage and beam sites
are nests of the labware model (`labware_model.holders.Nest`).
"""

from ros_bridge.bluesky.device import LabwareTransferRobot, TransferTask
from ros_bridge.bluesky.plan import robot_task, sample_exchange_plan
from ros_bridge.bluesky.status import ActionFailed, ActionStatus

__all__ = [
    "ActionFailed",
    "ActionStatus",
    "LabwareTransferRobot",
    "TransferTask",
    "robot_task",
    "sample_exchange_plan",
]
