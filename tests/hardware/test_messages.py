"""Message conversions, the RosClock rate and the process environment (no DDS traffic).

The conversion tests need the ROS message packages (skipped without them); the
environment and import tests run everywhere.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys

import numpy as np
import pytest

from pmnav_bt.hardware.env import BOOTSTRAP_FLAG, domain_id_for, ros_env
from pmnav_bt.seams import CameraIntrinsics, Pose2D


def test_hardware_modules_do_not_import_rclpy_at_import_time():
    code = (
        "import sys\n"
        "import pmnav_bt.hardware.env, pmnav_bt.hardware.qos, pmnav_bt.hardware.messages\n"
        "import pmnav_bt.hardware.clock, pmnav_bt.hardware.create3, pmnav_bt.hardware.runtime\n"
        "import pmnav_bt.hardware.node, pmnav_bt.hardware.sim_create3\n"
        "import pmnav_bt.hardware.testing\n"
        "bad = [m for m in sys.modules if m.split('.')[0] in ('rclpy', 'sensor_msgs')]\n"
        "print(bad)\n"
        "sys.exit(1 if bad else 0)\n"
    )
    env = ros_env(domain_id=domain_id_for(os.getpid()), discovery_range="LOCALHOST")
    r = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60
    )
    assert r.returncode == 0, r.stdout + r.stderr


def test_ros_env_sets_libraries_domain_and_discovery():
    env = ros_env({"PATH": "/usr/bin", "LD_LIBRARY_PATH": "/opt/x"}, domain_id=42)
    parts = env["LD_LIBRARY_PATH"].split(os.pathsep)
    assert parts[-1] == "/opt/x" and os.path.join(sys.prefix, "lib") in parts
    assert env[BOOTSTRAP_FLAG] == "1"
    assert env["ROS_DOMAIN_ID"] == "42"
    assert env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    assert env["RMW_IMPLEMENTATION"] == "rmw_fastrtps_cpp"
    assert ros_env({}, discovery_range=None).get("ROS_AUTOMATIC_DISCOVERY_RANGE") is None
    with pytest.raises(ValueError):
        ros_env({}, domain_id=300)
    assert all(1 <= domain_id_for(k) <= 101 for k in range(500))


@pytest.fixture
def msgs(ros_required):
    from pmnav_bt.hardware import messages

    return messages


def _stamp():
    from builtin_interfaces.msg import Time

    return Time(sec=12, nanosec=500_000_000)


def test_colour_images_decode_with_row_padding(msgs):
    rgb = np.random.default_rng(0).integers(0, 255, (5, 7, 3), dtype=np.uint8)
    m = msgs.image_message(rgb, "rgb8", _stamp(), "cam")
    assert np.array_equal(msgs.rgb_from_image(m), rgb)
    assert msgs.stamp_to_sec(m.header.stamp) == pytest.approx(12.5)
    # bgr8 with 3 bytes of padding per row
    bgr = rgb[:, :, ::-1]
    padded = np.zeros((5, 7 * 3 + 3), np.uint8)
    padded[:, : 7 * 3] = bgr.reshape(5, -1)
    m = msgs.image_message(padded, "bgr8", _stamp(), "cam")
    m.width, m.step = 7, 7 * 3 + 3
    assert np.array_equal(msgs.rgb_from_image(m), rgb)
    m.encoding = "yuv422"
    with pytest.raises(msgs.ImageFormatError, match="yuv422"):
        msgs.rgb_from_image(m)


def test_depth_in_metres_and_millimetres(msgs):
    d = np.array([[1.5, 2.0], [np.nan, 9.25]], np.float32)
    got = msgs.depth_from_image(msgs.image_message(d, "32FC1", _stamp(), "cam"))
    assert np.allclose(got, d, equal_nan=True)
    mm = np.array([[1500, 0], [65535, 250]], "<u2")
    got = msgs.depth_from_image(msgs.image_message(mm, "16UC1", _stamp(), "cam"))
    assert got[0, 0] == pytest.approx(1.5) and math.isnan(got[0, 1])
    assert got[1, 1] == pytest.approx(0.25) and got.dtype == np.float32


def test_segmentation_and_camera_info(msgs):
    seg = np.array([[0, 7], [300, 2]], "<u2")
    got = msgs.labels_from_image(msgs.image_message(seg, "16UC1", _stamp(), "cam"))
    assert got.dtype == np.int32 and got.tolist() == [[0, 7], [300, 2]]
    k = CameraIntrinsics.from_hfov(320, 240, math.radians(60))
    info = msgs.camera_info_message(k, _stamp(), "cam")
    assert msgs.intrinsics_from_camera_info(info) == pytest.approx(k)
    half = msgs.intrinsics_from_camera_info(info, 160, 120)
    assert half.fx == pytest.approx(k.fx / 2) and half.width == 160
    info.k = [0.0] * 9
    assert msgs.intrinsics_from_camera_info(info) is None


def test_poses_and_quaternions(msgs):
    for yaw in (-3.0, -1.0, 0.0, 0.5, 3.1):
        q = msgs.quaternion_from_yaw(yaw)
        assert msgs.yaw_from_quaternion(q) == pytest.approx(yaw)
    path = msgs.path_message([Pose2D(1, 2, 0.3), Pose2D(3, 4, -1.0)], _stamp(), "map")
    assert path.header.frame_id == "map" and len(path.poses) == 2
    assert path.poses[1].pose.position.y == 4.0
    tf = msgs.transform_stamped(Pose2D(1, 2, 0.5), _stamp(), "map", "odom")
    assert tf.child_frame_id == "odom"
    assert msgs.yaw_from_quaternion(tf.transform.rotation) == pytest.approx(0.5)


def test_ros_clock_keeps_its_rate_and_can_be_interrupted(domain_id):
    import threading
    import time

    from rclpy.node import Node

    from pmnav_bt.hardware.clock import RosClock
    from pmnav_bt.hardware.runtime import RosRuntime

    rt = RosRuntime(args=[], domain_id=domain_id)
    try:
        clock = RosClock(Node("clock_test", context=rt.context))
        assert abs(clock.now() - time.time()) < 0.5
        t0 = time.monotonic()
        for _ in range(5):
            time.sleep(0.02)  # a tick's work does not stretch the period
            clock.wait(0.05)
        assert time.monotonic() - t0 == pytest.approx(0.25, abs=0.04)
        threading.Timer(0.1, clock.interrupt).start()
        t0 = time.monotonic()
        clock.wait(5.0)
        assert time.monotonic() - t0 < 1.0 and clock.interrupted
        clock.clear()
        assert not clock.interrupted
    finally:
        rt.shutdown()


def test_a_frame_shrunk_for_the_tree_keeps_ranges_and_labels_unmixed():
    from pmnav_bt.hardware.messages import shrink_frame

    rgb = np.zeros((480, 640, 3), np.uint8)
    rgb[:, 320:] = 200
    depth = np.where(np.arange(640) < 320, 1.0, 5.0).astype(np.float32)[None].repeat(480, 0)
    seg = np.where(np.arange(640) < 320, 3, 7).astype(np.int32)[None].repeat(480, 0)
    small, d, s = shrink_frame(rgb, depth, seg, 320)
    assert small.shape == (240, 320, 3) and d.shape == s.shape == (240, 320)
    assert set(np.unique(d)) == {1.0, 5.0} and set(np.unique(s)) == {3, 7}  # no blends
    assert d[:, 159].max() == 1.0 and d[:, 160].min() == 5.0
    assert shrink_frame(rgb, None, None, 320)[1:] == (None, None)


def test_the_robot_cameras_width_sets_the_readers_range():
    from pmnav_bt.config import load_config
    from pmnav_bt.hardware.create3 import Create3Options
    from pmnav_bt.hardware.node import camera_config
    from pmnav_bt.perception.read_range import search_settings

    cfg = load_config(None, ["grounder.backend=ocr"])
    assert camera_config(cfg, None, Create3Options()) is cfg  # no frame yet
    at320 = camera_config(cfg, 320, Create3Options())
    assert (at320.sim.width, at320.sim.reading_width) == (320, 320)
    assert search_settings(at320).search_range == 2.0
    shrunk = camera_config(cfg, 640, Create3Options(frame_width=320))
    assert (shrunk.sim.width, shrunk.sim.reading_width) == (320, 640)
    assert search_settings(shrunk).search_range == 3.0
