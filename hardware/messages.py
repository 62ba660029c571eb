"""Conversions between ROS 2 messages and the core's types (numpy images, Pose2D, intrinsics).

Image encodings (REP-118 for depth):

- colour: ``rgb8``, ``bgr8``, ``rgba8``, ``bgra8``, ``mono8`` -> (H, W, 3) uint8 RGB;
- depth: ``32FC1`` metres (NaN or inf where there is no return), ``16UC1`` millimetres
  (0 = no return, read as NaN) -> (H, W) float32 metres;
- segmentation (simulator only): ``16UC1``, ``32SC1``, ``mono8``/``8UC1`` label ids ->
  (H, W) int32, with the id -> label map published as JSON on a latched topic.

The functions take and return message *instances*; only the builders import the
message modules, so importing this module never starts ROS.
"""

from __future__ import annotations

import array
import math

import numpy as np

from pmnav_bt.errors import PmNavError
from pmnav_bt.seams import CameraIntrinsics, Pose2D


class ImageFormatError(PmNavError):
    """An image message whose encoding or size this project cannot read."""


_COLOUR = {"rgb8": (3, False), "bgr8": (3, True), "rgba8": (4, False), "bgra8": (4, True)}


def stamp_to_sec(stamp) -> float:
    """builtin_interfaces/Time -> seconds."""
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9


def sec_to_stamp(t: float):
    """Seconds -> builtin_interfaces/Time."""
    from builtin_interfaces.msg import Time

    ns = int(round(t * 1e9))
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def yaw_from_quaternion(q) -> float:
    """Yaw (rad) of a geometry_msgs/Quaternion (rotation about +z)."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def quaternion_from_yaw(yaw: float):
    from geometry_msgs.msg import Quaternion

    return Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2.0), w=math.cos(yaw / 2.0))


def pose_from_odometry(msg) -> Pose2D:
    """nav_msgs/Odometry -> Pose2D in the odometry frame."""
    p = msg.pose.pose
    return Pose2D(float(p.position.x), float(p.position.y), yaw_from_quaternion(p.orientation))


def _rows(msg, itemsize: int, channels: int) -> np.ndarray:
    """The image's bytes as an (H, W*channels*itemsize) uint8 array, row stride removed."""
    h, w = int(msg.height), int(msg.width)
    row = w * channels * itemsize
    step = int(msg.step) or row
    buf = np.frombuffer(msg.data, dtype=np.uint8)
    if step < row or buf.size < step * (h - 1) + row:
        raise ImageFormatError(
            f"image {w}x{h} {msg.encoding}: {buf.size} bytes with step {step} is too small"
        )
    if step * h > buf.size:
        buf = np.concatenate([buf, np.zeros(step * h - buf.size, np.uint8)])
    return buf[: step * h].reshape(h, step)[:, :row]


def _typed(msg, dtype: str, channels: int = 1) -> np.ndarray:
    dt = np.dtype(dtype).newbyteorder(">" if msg.is_bigendian else "<")
    raw = np.ascontiguousarray(_rows(msg, dt.itemsize, channels))
    out = raw.view(dt).reshape(int(msg.height), int(msg.width), channels)
    return out[:, :, 0] if channels == 1 else out


def rgb_from_image(msg) -> np.ndarray:
    """sensor_msgs/Image (colour or mono8) -> (H, W, 3) uint8 RGB."""
    enc = msg.encoding.lower()
    if enc in _COLOUR:
        ch, bgr = _COLOUR[enc]
        img = _typed(msg, "u1", ch)[:, :, :3]
        return np.ascontiguousarray(img[:, :, ::-1] if bgr else img)
    if enc in ("mono8", "8uc1"):
        g = _typed(msg, "u1")
        return np.repeat(g[:, :, None], 3, axis=2)
    raise ImageFormatError(
        f"camera image encoding {msg.encoding!r} is not supported; "
        "use rgb8, bgr8, rgba8, bgra8 or mono8"
    )


def depth_from_image(msg) -> np.ndarray:
    """sensor_msgs/Image depth -> (H, W) float32 metres (NaN where there is no return)."""
    enc = msg.encoding.upper()
    if enc == "32FC1":
        return _typed(msg, "f4").astype(np.float32, copy=True)
    if enc in ("16UC1", "MONO16"):
        mm = _typed(msg, "u2").astype(np.float32)
        mm[mm == 0] = np.nan
        return mm / 1000.0
    raise ImageFormatError(
        f"depth image encoding {msg.encoding!r} is not supported; use 32FC1 (m) or 16UC1 (mm)"
    )


def labels_from_image(msg) -> np.ndarray:
    """sensor_msgs/Image of label ids -> (H, W) int32."""
    enc = msg.encoding.upper()
    kinds = {"16UC1": "u2", "MONO16": "u2", "32SC1": "i4", "8UC1": "u1", "MONO8": "u1"}
    if enc not in kinds:
        raise ImageFormatError(
            f"segmentation encoding {msg.encoding!r} is not supported; use 16UC1, 32SC1 or 8UC1"
        )
    return _typed(msg, kinds[enc]).astype(np.int32)


def shrink_frame(rgb: np.ndarray, depth, seg, width: int):
    """A camera frame shrunk to ``width`` pixels (aspect kept): colour by area averaging,
    depth and labels by the nearest pixel (no mixed ranges or labels at edges)."""
    import cv2

    h, w = rgb.shape[:2]
    size = (int(width), max(1, round(h * width / w)))

    def nearest(a):
        if a is None:
            return None
        rows = ((np.arange(size[1]) + 0.5) * a.shape[0] / size[1]).astype(int)
        cols = ((np.arange(size[0]) + 0.5) * a.shape[1] / size[0]).astype(int)
        return np.ascontiguousarray(a[rows][:, cols])

    return cv2.resize(rgb, size, interpolation=cv2.INTER_AREA), nearest(depth), nearest(seg)


def intrinsics_from_camera_info(msg, width: int | None = None, height: int | None = None):
    """sensor_msgs/CameraInfo -> CameraIntrinsics, scaled to ``width`` x ``height`` if the
    image size differs from the calibration (binning); None for an uncalibrated camera."""
    k = list(msg.k)
    if len(k) != 9 or k[0] <= 0.0 or k[4] <= 0.0 or msg.width == 0 or msg.height == 0:
        return None
    w = int(width or msg.width)
    h = int(height or msg.height)
    sx, sy = w / float(msg.width), h / float(msg.height)
    return CameraIntrinsics(w, h, k[0] * sx, k[4] * sy, k[2] * sx, k[5] * sy)


# -- builders (import the message packages) ---------------------------------------------------


def _data(arr: np.ndarray):
    # array.array from bytes is a memcpy; rclpy accepts it without a per-element check.
    return array.array("B", np.ascontiguousarray(arr).tobytes())


def image_message(arr: np.ndarray, encoding: str, stamp, frame_id: str):
    """numpy image -> sensor_msgs/Image (little-endian)."""
    from sensor_msgs.msg import Image

    a = np.ascontiguousarray(arr)
    msg = Image()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.height, msg.width = int(a.shape[0]), int(a.shape[1])
    msg.encoding = encoding
    msg.is_bigendian = 0
    msg.step = int(a.strides[0])
    msg.data = _data(a)
    return msg


def camera_info_message(k: CameraIntrinsics, stamp, frame_id: str):
    """CameraIntrinsics -> sensor_msgs/CameraInfo (plumb bob, no distortion)."""
    from sensor_msgs.msg import CameraInfo

    msg = CameraInfo()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.width, msg.height = int(k.width), int(k.height)
    msg.distortion_model = "plumb_bob"
    msg.d = [0.0] * 5
    msg.k = [k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0]
    msg.r = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    msg.p = [k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    return msg


def pose_stamped(pose: Pose2D, stamp, frame_id: str):
    from geometry_msgs.msg import PoseStamped

    msg = PoseStamped()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.pose.position.x, msg.pose.position.y = float(pose.x), float(pose.y)
    msg.pose.orientation = quaternion_from_yaw(pose.yaw)
    return msg


def path_message(poses: list[Pose2D], stamp, frame_id: str):
    """A list of poses -> nav_msgs/Path."""
    from nav_msgs.msg import Path

    msg = Path()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.poses = [pose_stamped(p, stamp, frame_id) for p in poses]
    return msg


def transform_stamped(pose: Pose2D, stamp, parent: str, child: str):
    from geometry_msgs.msg import TransformStamped

    msg = TransformStamped()
    msg.header.stamp = stamp
    msg.header.frame_id = parent
    msg.child_frame_id = child
    msg.transform.translation.x = float(pose.x)
    msg.transform.translation.y = float(pose.y)
    msg.transform.rotation = quaternion_from_yaw(pose.yaw)
    return msg
