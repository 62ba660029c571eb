"""Plates read at a target's place that named nothing, in its TARGET_NOT_FOUND failure."""

from __future__ import annotations

import numpy as np

from pmnav_bt.failures import Failure, FailureCode
from pmnav_bt.perception.misreads import Misreads
from pmnav_bt.planning.resolve import sign_text
from pmnav_bt.seams import CameraIntrinsics, Detection, Entity, Observation, Pose2D

ROOM8 = Entity.room("room8")  # its door at (31, 1.2)


def _observation(stamp: float):
    k = CameraIntrinsics.from_hfov(64, 48, 1.0)
    return Observation(np.zeros((48, 64, 3), np.uint8), Pose2D(0.0, 0.0, 0.0), stamp, k)


def _plate(text):
    """A plate read 2 m straight ahead that names nothing of the map."""
    return Detection(text, (10, 10, 60, 40), 0.9, point=(2.0, 0.0, 0.0))


def _misreads(fig2_map):
    """'180' in two frames and '1O8' in one, 0.8 m from room8's door; '108 B' 5 m away,
    and reads before localization (not placed on the map)."""
    by_door = Misreads(fig2_map, lambda: (29.8, 1.2, 0.0))  # the plate at (31.8, 1.2)
    for k, text in enumerate(["180", "180", "1O8"]):
        by_door.frame(_observation(float(k)), [], [_plate(text)])
    by_door.frame(_observation(1.0), [], [_plate("180")])  # the same frame again
    far = Misreads(fig2_map, lambda: (24.0, 0.0, 0.0))  # the plate at (26, 0)
    far.frame(_observation(0.0), [], [_plate("108 B")])
    by_door.map_T_odom = lambda: None
    by_door.frame(_observation(5.0), [], [_plate("18")])
    return by_door, far


def test_the_reads_at_the_target_are_named_with_the_sign_the_map_has_there(fig2_map):
    by_door, far = _misreads(fig2_map)
    mapped = sign_text(fig2_map.building, ROOM8)
    assert by_door.words(ROOM8) == f"sign '{mapped}' read as '180' twice and as '1O8' once"
    assert far.words(ROOM8) is None
    assert by_door.words(Entity.room("room7")) is None  # its door 7.8 m away


def test_a_target_not_found_says_what_was_read_there_and_other_failures_do_not(fig2_map):
    by_door, _ = _misreads(fig2_map)
    lost = Failure(FailureCode.TARGET_NOT_FOUND, "room8 not seen in 12 views")
    spent = Failure(FailureCode.BUDGET_EXCEEDED, "500 actions", cause=lost)
    out = by_door.explain(spent, ROOM8)
    assert out.message == "500 actions"
    assert out.cause.message.startswith("room8 not seen in 12 views; sign '")
    assert "read as '180' twice" in str(out)
    assert by_door.explain(lost, None) == lost
    blocked = Failure(FailureCode.BLOCKED, "obstacle 0.9 m ahead")
    assert by_door.explain(blocked, ROOM8) == blocked
