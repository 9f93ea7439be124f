"""Pinhole camera model and RGB-D rendering of a PyBullet scene from an OpenCV optical frame.

The projection matrix is built from the intrinsics (fx, fy, cx, cy) rather than from a field of
view, so the rendered image is exactly what ``CameraIntrinsics.matrix()`` predicts: a point at
``K @ p / p_z`` in OpenCV pixel coordinates (pixel centres at integers) lands on that pixel.
Depth comes back as metres along the optical axis (OpenCV z), converted from the GL buffer.

TinyRenderer in DIRECT mode is the default, since CI has no GPU. Call on the thread that owns
the PyBullet client.
"""

from __future__ import annotations

import cv2
import numpy as np
import pybullet as p

from robot_port.types import CameraIntrinsics
from tiago_description.transforms import invert

# OpenCV optical frame (x right, y down, z forward) to GL camera frame (x right, y up, z back).
T_OPTICAL_GL = np.diag([1.0, -1.0, -1.0, 1.0])
# Where a renderer samples pixel (0, 0), in window coordinates from the left and top edges.
# OpenGL samples pixel centres (0.5, 0.5). PyBullet's TinyRenderer samples at integer window
# coordinates counted from the bottom and then flips the rows, which is (0, 1) from the top;
# measured with the edges of a large box at 40 sub-pixel positions. The EGL plugin
# (ER_BULLET_HARDWARE_OPENGL, Mesa on CPU) follows the OpenGL rule, checked the same way.
# Using the right offset removes a 0.5 px shift that would otherwise bias every marker pose.
GL_SAMPLE_OFFSET = (0.5, 0.5)
TINY_RENDERER_SAMPLE_OFFSET = (0.0, 1.0)


def gl_projection(
    intrinsics: CameraIntrinsics, sample_offset: tuple[float, float] = GL_SAMPLE_OFFSET
) -> np.ndarray:
    """4x4 OpenGL projection matrix (row-major) equivalent to K and the clip range.

    ``sample_offset`` is where the renderer samples pixel (0, 0), in window coordinates
    counted from the left and from the top edge; see the module constants.
    """
    w, h, n, f = intrinsics.width, intrinsics.height, intrinsics.near, intrinsics.far
    offset_x, offset_y = sample_offset
    projection = np.zeros((4, 4))
    projection[0, 0] = 2.0 * intrinsics.fx / w
    projection[0, 2] = 1.0 - 2.0 * (intrinsics.cx + offset_x) / w
    projection[1, 1] = 2.0 * intrinsics.fy / h
    projection[1, 2] = 2.0 * (intrinsics.cy + offset_y) / h - 1.0
    projection[2, 2] = -(f + n) / (f - n)
    projection[2, 3] = -2.0 * f * n / (f - n)
    projection[3, 2] = -1.0
    return projection


def gl_depth_to_metres(depth_buffer: np.ndarray, near: float, far: float) -> np.ndarray:
    """Convert GL depth-buffer values in [0, 1] to distance along the optical axis in metres."""
    depth = np.asarray(depth_buffer, dtype=np.float64)
    return (far * near / (far - (far - near) * depth)).astype(np.float32)


def render_rgbd(
    client_id: int,
    T_world_optical: np.ndarray,
    intrinsics: CameraIntrinsics,
    supersample: int = 1,
    renderer: int = p.ER_TINY_RENDERER,
    shadow: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Render (rgb uint8 HxWx3, depth_m float32 HxW) seen from the optical frame pose.

    With ``supersample`` > 1 the scene is rendered that many times larger and averaged down,
    which smooths edges and gives sub-pixel accurate marker corners (at about that factor
    squared in render time). Pixels that hit nothing read ``intrinsics.far``.

    ``shadow`` casts shadows. TinyRenderer's default casts them, which doubles a head-camera frame
    (station view: 222 vs 117 ms); they only change pixels by a few grey levels.
    """
    if supersample < 1:
        raise ValueError(f"supersample must be >= 1, got {supersample}")
    render_intrinsics = intrinsics.scaled(supersample) if supersample > 1 else intrinsics
    sample_offset = TINY_RENDERER_SAMPLE_OFFSET if renderer == p.ER_TINY_RENDERER else GL_SAMPLE_OFFSET
    T_world_gl = np.asarray(T_world_optical, dtype=float) @ T_OPTICAL_GL
    view_matrix = invert(T_world_gl)
    _, _, rgba, depth_buffer, _ = p.getCameraImage(
        render_intrinsics.width,
        render_intrinsics.height,
        viewMatrix=view_matrix.T.flatten().tolist(),
        projectionMatrix=gl_projection(render_intrinsics, sample_offset).T.flatten().tolist(),
        renderer=renderer,
        flags=p.ER_NO_SEGMENTATION_MASK,
        shadow=int(shadow),
        physicsClientId=client_id,
    )
    shape = (render_intrinsics.height, render_intrinsics.width)
    rgb = np.asarray(rgba, dtype=np.uint8).reshape(shape + (4,))[:, :, :3]
    depth_m = gl_depth_to_metres(
        np.asarray(depth_buffer, dtype=np.float32).reshape(shape), intrinsics.near, intrinsics.far
    )
    if supersample > 1:
        size = (intrinsics.width, intrinsics.height)
        rgb = cv2.resize(rgb, size, interpolation=cv2.INTER_AREA)
        depth_m = cv2.resize(depth_m, size, interpolation=cv2.INTER_AREA)
    return np.ascontiguousarray(rgb), depth_m


def optical_frame_looking_at(
    eye: np.ndarray, target: np.ndarray, roll: float = 0.0, up: tuple[float, float, float] = (0.0, 0.0, 1.0)
) -> np.ndarray:
    """T_world_optical of a camera at ``eye`` whose optical axis passes through ``target``.

    With ``roll`` 0 the image is upright (optical y points as far down ``-up`` as it can);
    ``roll`` turns the camera about its optical axis.
    """
    eye_point = np.asarray(eye, dtype=float)
    z_axis = np.asarray(target, dtype=float) - eye_point
    z_axis /= np.linalg.norm(z_axis)
    up_axis = np.asarray(up, dtype=float)
    x_axis = np.cross(-up_axis, z_axis)
    if np.linalg.norm(x_axis) < 1e-9:
        raise ValueError("the optical axis is parallel to 'up'; the camera roll is undefined")
    x_axis /= np.linalg.norm(x_axis)
    y_axis = np.cross(z_axis, x_axis)
    cos_roll, sin_roll = np.cos(roll), np.sin(roll)
    about_optical_axis = np.array([[cos_roll, -sin_roll, 0.0], [sin_roll, cos_roll, 0.0], [0.0, 0.0, 1.0]])
    rotation = np.column_stack([x_axis, y_axis, z_axis]) @ about_optical_axis
    transform = np.eye(4)
    transform[:3, :3] = rotation
    transform[:3, 3] = eye_point
    return transform
