"""Localization from landmarks: the fix, consistency, and misread signs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.geometry import se2_apply, se2_inverse
from pmnav_bt.pose.landmark_fix import Sighting, fix_pose
from pmnav_bt.seams import Entity, Pose2D

R = Entity.room

TRUE = (12.0, -3.0, math.radians(35))  # map_T_odom


def seen(entity, map_xy, noise=(0.0, 0.0)):
    odom = se2_apply(se2_inverse(TRUE), map_xy) + np.asarray(noise)
    return Sighting(entity, tuple(map_xy), (float(odom[0]), float(odom[1])))


def test_two_landmarks_fix_the_pose():
    fix = fix_pose([seen(R("a"), (10, 2)), seen(R("b"), (14, -1.2))])
    assert fix is not None and fix.entities == (R("a"), R("b"))
    assert fix.map_T_odom == pytest.approx(TRUE, abs=1e-9)
    p = fix.map_pose(Pose2D(1.0, 0.0, 0.0))
    assert (p.x, p.y) == pytest.approx(tuple(se2_apply(TRUE, (1.0, 0.0))))


def test_one_landmark_is_not_enough_even_seen_twice():
    assert fix_pose([seen(R("a"), (10, 2)), seen(R("a"), (10, 2), (0.1, 0))]) is None
    assert fix_pose([]) is None


def test_a_misread_sign_is_dropped():
    good = [seen(R("a"), (10, 2)), seen(R("b"), (14, -1.2)), seen(R("c"), (20, 2))]
    wrong = Sighting(R("d"), (40.0, 9.0), good[0].odom_xy)  # read 'd' where 'a' is
    fix = fix_pose(good + [wrong])
    assert fix is not None and R("d") not in fix.entities and len(fix.entities) == 3
    assert fix.map_T_odom == pytest.approx(TRUE, abs=1e-6)


def test_inconsistent_pair_gives_no_fix():
    a = seen(R("a"), (10, 2))
    b = Sighting(R("b"), (30.0, 2.0), seen(R("b"), (14, 2)).odom_xy)  # 16 m off
    assert fix_pose([a, b]) is None


def test_noise_is_averaged():
    rng = np.random.default_rng(0)
    ss = [seen(R(str(i)), (10 + 3 * i, 1.2 * (-1) ** i), rng.normal(0, 0.05, 2)) for i in range(6)]
    fix = fix_pose(ss)
    assert fix is not None and fix.residual < 0.15
    assert fix.map_T_odom[:2] == pytest.approx(TRUE[:2], abs=0.15)
