"""The geometric refiner: the target's bearing and range come from one point."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.perception.refiners.geometric import GeometricRefiner
from pmnav_bt.seams import CameraIntrinsics, Detection, Entity, EntityKind, Observation, Pose2D

K = CameraIntrinsics.from_hfov(320, 240, math.radians(60.0))


def _obs(depth_m: float) -> Observation:
    depth = np.full((240, 320), depth_m, np.float32)
    return Observation(np.zeros((240, 320, 3), np.uint8), Pose2D(0, 0, 0), 0.0, K, depth=depth)


def test_a_door_placed_beside_its_sign_is_refined_to_the_door_not_the_sign():
    # The plate (read, centred in the view 1 m ahead) and its door 0.8 m to its right,
    # partly out of view: the detection keeps the plate's box, the point is the door's.
    door = (1.0, -0.8, 0.0)
    room = Entity(EntityKind.ROOM, "room10")
    det = Detection("110", (150.0, 110.0, 170.0, 130.0), 0.9, None, room, door)
    r = GeometricRefiner().refine(_obs(1.0), det)
    seen = (r.range * math.cos(r.bearing), r.range * math.sin(r.bearing))
    assert seen == pytest.approx(door[:2], abs=1e-6)


def test_without_a_point_the_box_and_depth_decide():
    det = Detection("door", (250.0, 100.0, 270.0, 140.0), 0.9)
    r = GeometricRefiner().refine(_obs(2.0), det)
    assert r.bearing == pytest.approx(K.pixel_bearing(260.0))
    assert r.range == pytest.approx(math.hypot(2.0, (K.cx - 260.0) * 2.0 / K.fx))
