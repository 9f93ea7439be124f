"""The head camera's topics: colour, intrinsics and depth registered to the colour image (PAL's
names, robot_port.tiago_interfaces), rendered only while someone subscribes.

Why only then, and at most 5 a second: a render costs about 0.1 s of CPU, the skills in the
simulator's process take their frames through the hardware port, and a topic nobody reads is CPU a
campaign loses. A wall-clock timer asks the sim thread for a frame while someone listens; the frame
goes out as soon as it is rendered.
Lives on: the rclpy executor threads of the sim node.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image

from robot_port.tiago_interfaces import CAMERA_DEPTH, CAMERA_IMAGE, CAMERA_INFO
from tiago_description.kinematics import CAMERA_FRAME
from tiago_sim.sim_node.localisation_topics import stamp_of
from tiago_sim.sim_node.sim_thread import SimThread

CAMERA_RATE_HZ = 5.0
"""Frames a second of wall time while subscribed, at most (a robot's camera gives 30; a render
costs 0.1 s of CPU)."""


class CameraTopics:
    """Publishes the head camera while it has subscribers."""

    def __init__(self, node: Node, sim_thread: SimThread, rate_hz: float = CAMERA_RATE_HZ) -> None:
        self.sim_thread = sim_thread
        self.image_pub = node.create_publisher(Image, CAMERA_IMAGE, 2)
        self.info_pub = node.create_publisher(CameraInfo, CAMERA_INFO, 2)
        self.depth_pub = node.create_publisher(Image, CAMERA_DEPTH, 2)
        self._pending: Any = None
        node.create_timer(1.0 / rate_hz, self._tick)

    def _wanted(self) -> bool:
        return any(pub.get_subscription_count() for pub in (self.image_pub, self.info_pub, self.depth_pub))

    def _tick(self) -> None:
        if not self._wanted() or (self._pending is not None and not self._pending.done()):
            return
        self._pending = self.sim_thread.call(lambda sim: (float(sim.sim_time), *sim.render_head_camera()))
        self._pending.add_done_callback(self._rendered)

    def _rendered(self, frame: Any) -> None:
        """Publish a rendered frame at once (on the thread that rendered it)."""
        if frame.exception() is None:
            self._publish(*frame.result())

    def _publish(self, sim_time: float, rgb: np.ndarray, depth: np.ndarray, intrinsics: Any) -> None:
        image = _image(rgb, "rgb8", sim_time)
        self.image_pub.publish(image)
        self.depth_pub.publish(_image(depth.astype(np.float32), "32FC1", sim_time))
        info = CameraInfo()
        info.header = image.header
        info.height, info.width = image.height, image.width
        info.distortion_model = "plumb_bob"
        info.d = [0.0] * 5
        fx, fy = float(intrinsics.fx), float(intrinsics.fy)
        cx, cy = float(intrinsics.cx), float(intrinsics.cy)
        info.k = [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0]
        info.r = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        info.p = [fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
        self.info_pub.publish(info)


def _image(pixels: np.ndarray, encoding: str, sim_time: float) -> Image:
    """A sensor_msgs/Image of `pixels` (rows, columns[, channels]) in the camera's optical frame."""
    image = Image()
    image.header.stamp = stamp_of(sim_time)
    image.header.frame_id = CAMERA_FRAME
    image.height, image.width = int(pixels.shape[0]), int(pixels.shape[1])
    image.encoding = encoding
    image.step = image.width * pixels.itemsize * (pixels.shape[2] if pixels.ndim == 3 else 1)
    image.data = np.ascontiguousarray(pixels).tobytes()
    return image
