"""Synthetic frames for the perception tests: a plain wall with real sign textures."""

from __future__ import annotations

import math
from types import SimpleNamespace

import cv2
import numpy as np
import pytest

from pmnav_bt.seams import CameraIntrinsics, Observation, Pose2D
from pmnav_bt.sim.textures import make_sign

K = CameraIntrinsics.from_hfov(320, 240, math.radians(60.0))
WALL_RGB = (200, 196, 180)
RANGE = 1.8  # m to the wall


def wall_frame(
    signs: list[tuple[str, float]],
    depth: bool = True,
    range_m: float = RANGE,
    k: CameraIntrinsics = K,
) -> Observation:
    """A camera ``k`` facing a plain wall ``range_m`` away, with sign plates at lateral
    offsets (m, left positive) centred at camera height."""
    K = k  # noqa: N806 - the module's name for the camera
    rgb = np.full((K.height, K.width, 3), WALL_RGB, np.uint8)
    px_per_m = K.fx / range_m
    for text, y_left in signs:
        tex = make_sign(text)
        w = int(round(tex.width_m * px_per_m))
        h = int(round(tex.height_m * px_per_m))
        img = cv2.resize(tex.image, (w, h), interpolation=cv2.INTER_AREA)
        u0 = int(round(K.cx - y_left * px_per_m - w / 2))
        v0 = int(round(K.cy - h / 2))
        su0, sv0 = max(u0, 0), max(v0, 0)
        su1, sv1 = min(u0 + w, K.width), min(v0 + h, K.height)
        rgb[sv0:sv1, su0:su1] = img[sv0 - v0 : sv1 - v0, su0 - u0 : su1 - u0]
    d = np.full((K.height, K.width), range_m, np.float32) if depth else None
    return Observation(rgb, Pose2D(0.0, 0.0, 0.0), 0.0, K, depth=d, camera_height=1.6)


@pytest.fixture
def wall():
    """``wall.frame(signs, depth=True, range_m=RANGE, k=K)``, with the camera ``wall.K`` at
    ``wall.RANGE`` m."""
    return SimpleNamespace(frame=wall_frame, K=K, RANGE=RANGE)
