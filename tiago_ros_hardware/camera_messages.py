"""The head camera's messages as the port's CameraFrame: a colour image and the depth image of the
same frame, with the camera's intrinsics.

Why apart from the adapter: the two image topics arrive independently (the first message of each
may belong to different frames), and turning the messages into arrays is plain decoding.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robot_port.types import CameraIntrinsics
from tiago_ros_hardware.topics import TopicHistory


def frame_pair(
    images: TopicHistory, depths: TopicHistory, since_s: float, timeout_s: float
) -> tuple[float, Any, Any]:
    """A colour image rendered after `since_s` and the depth image of the same stamp."""
    while True:
        stamp, image = images.newer_than(since_s - 1e-9, timeout_s)
        depth_stamp, depth = depths.newer_than(stamp - 1e-9, timeout_s)
        if abs(depth_stamp - stamp) < 1e-6:
            return stamp, image, depth
        since_s = depth_stamp  # the depth is of a later frame: take that frame's pair


def decoded(image: Any, depth: Any, info: Any) -> tuple[np.ndarray, np.ndarray, CameraIntrinsics]:
    """RGB (8 bit, 3 channels) and depth (metres, float32) arrays, and the intrinsics of `info`."""
    rgb = np.frombuffer(bytes(image.data), dtype=np.uint8).reshape(image.height, image.width, 3)
    metres = np.frombuffer(bytes(depth.data), dtype=np.float32).reshape(depth.height, depth.width)
    k = info.k
    intrinsics = CameraIntrinsics(width=info.width, height=info.height, fx=k[0], fy=k[4], cx=k[2], cy=k[5])
    return rgb.copy(), metres.copy(), intrinsics
