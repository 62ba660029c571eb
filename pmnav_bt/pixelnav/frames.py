"""The policy's view of a frame: a small RGB image, and the goal pixel in its coordinates.

Training frames are rendered at twice the policy's size and area-averaged down, the way a
camera frame of any size is shrunk at run time, so both see the same kind of image.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from pmnav_bt.seams import CameraIntrinsics, Pose2D

HFOV = math.radians(60.0)  # the simulated camera's (and the paper's)


def shrink(rgb: np.ndarray, width: int, height: int) -> np.ndarray:
    """An (H, W, 3) uint8 frame area-averaged to ``width`` x ``height``."""
    if rgb.shape[1] == width and rgb.shape[0] == height:
        return np.ascontiguousarray(rgb)
    return cv2.resize(rgb, (width, height), interpolation=cv2.INTER_AREA)


def scale_pixel(
    uv: tuple[float, float], src: CameraIntrinsics, width: int, height: int
) -> tuple[float, float]:
    """A pixel of a ``src`` frame in the coordinates of the same frame at ``width`` x ``height``."""
    sx, sy = width / src.width, height / src.height
    return (uv[0] + 0.5) * sx - 0.5, (uv[1] + 0.5) * sy - 0.5


def back_project(
    pose: Pose2D, k: CameraIntrinsics, u: float, v: float, depth: float, camera_height: float
) -> np.ndarray:
    """Map point (x, y, z) of pixel (u, v) seen at ``depth`` m along the optical axis."""
    yc = (k.cx - u) / k.fx * depth
    zc = (k.cy - v) / k.fy * depth
    c, s = math.cos(pose.yaw), math.sin(pose.yaw)
    return np.array(
        [pose.x + depth * c - yc * s, pose.y + depth * s + yc * c, camera_height + zc], float
    )


def project(
    pose: Pose2D, k: CameraIntrinsics, point: np.ndarray, camera_height: float
) -> tuple[float, float, float]:
    """Pixel (u, v) of a map point, and its depth along the optical axis (<= 0: behind)."""
    dx, dy = float(point[0]) - pose.x, float(point[1]) - pose.y
    c, s = math.cos(pose.yaw), math.sin(pose.yaw)
    xc, yc, zc = dx * c + dy * s, -dx * s + dy * c, float(point[2]) - camera_height
    if xc <= 1e-6:
        return math.nan, math.nan, xc
    return k.cx - k.fx * yc / xc, k.cy - k.fy * zc / xc, xc
