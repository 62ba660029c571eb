"""Pose correction: heading from two landmarks, scale bias, tolerance, walls, snapping."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.geometry import se2_apply, se2_inverse
from pmnav_bt.pose.correction import TOLERANCE_MIN_M, PoseTracker, Verified
from pmnav_bt.pose.snap import OffMapError, snap_to_corridor
from pmnav_bt.pose.walls import (
    axis_in_odom,
    corridor_centre,
    fit_wall_angle,
    heading_correction,
)
from pmnav_bt.seams import Pose2D


def test_heading_bias_is_corrected_after_two_landmarks():
    true = (1.0, -0.5, math.radians(6.0))  # the real map_T_odom: 6 degrees of heading error
    tracker = PoseTracker(map_T_odom=(1.0, -0.5, 0.0), sigma0=0.3)
    for k, m in enumerate([(5.0, 1.2), (14.0, -1.2)]):
        odom = tuple(se2_apply(se2_inverse(true), m))
        tracker.correct(Verified(odom, m, odometer=9.0 * k))
        if k == 0:
            assert abs(tracker.map_T_odom[2]) < 1e-9  # one landmark: position only
    assert abs(tracker.map_T_odom[2] - true[2]) < math.radians(0.5)
    far = (40.0, 0.0)  # a point far down the corridor now lands where it is
    np.testing.assert_allclose(
        se2_apply(tracker.map_T_odom, se2_apply(se2_inverse(true), far)), far, atol=0.3
    )


def test_odometry_scale_bias_is_estimated():
    tracker = PoseTracker(map_T_odom=(0.0, 0.0, 0.0))
    for k, x in enumerate([2.0, 14.0]):
        tracker.correct(Verified((x / 1.04, 1.2), (x, 1.2), odometer=float(k)))
    assert tracker.scale == pytest.approx(1.04, abs=0.01)


def test_verification_tolerance_follows_the_uncertainty():
    tracker = PoseTracker(map_T_odom=(0.0, 0.0, 0.0), sigma0=0.3, odometer0=0.0)
    near, far = tracker.verify_tolerance(1.0), tracker.verify_tolerance(60.0)
    assert near == TOLERANCE_MIN_M
    assert far > 3.0 > near  # beyond the old fixed 3 m after a long dead-reckoned leg
    assert tracker.verify_tolerance(1000.0) <= 8.0


def test_wall_line_fit_gives_the_angle_to_the_corridor_axis():
    rng = np.random.default_rng(0)
    a = math.radians(12.0)
    s = rng.uniform(0.5, 5.0, 300)
    wall = np.stack([s * math.cos(a), 1.2 + s * math.sin(a)], 1) + rng.normal(0, 0.01, (300, 2))
    clutter = rng.uniform(-1, 5, (60, 2))
    angle, n = fit_wall_angle(np.vstack([wall, clutter]))
    assert angle == pytest.approx(a, abs=math.radians(1.0))
    assert n >= 250
    # Views at odometry yaws 0 and pi/2 both see the same axis, mod pi.
    axis = axis_in_odom([(0.0, a, 300), (math.pi / 2, a - math.pi / 2, 200)])
    assert math.remainder(axis - a, math.pi) == pytest.approx(0.0, abs=1e-6)
    # The correction that lines the measured axis up with a corridor heading of pi.
    assert heading_correction(axis, 0.0, math.pi) == pytest.approx(-a, abs=1e-6)


@pytest.mark.parametrize("lateral", [-0.7, 0.0, 0.5])
def test_both_walls_give_the_way_back_to_the_corridors_centre_line(lateral):
    """A robot ``lateral`` m left of the centre line of a 2.4 m corridor, 8 deg off its
    axis: the two walls in view say the centre line is ``-lateral`` m to its left; one
    wall alone (a side corridor's mouth opposite) says nothing."""
    rng = np.random.default_rng(1)
    a = math.radians(8.0)
    u, n = np.array([math.cos(a), -math.sin(a)]), np.array([math.sin(a), math.cos(a)])

    def wall(y):  # a wall y m left of the centre line, in the robot's frame
        s = rng.uniform(0.8, 5.5, 250)
        return s[:, None] * u + (y - lateral) * n + rng.normal(0, 0.01, (250, 2))

    clutter = rng.uniform(-1, 5, (40, 2))
    angle, offset = corridor_centre(np.vstack([wall(1.2), wall(-1.2), clutter]))
    assert angle == pytest.approx(-a, abs=math.radians(1.0))
    assert offset == pytest.approx(-lateral, abs=0.05)
    assert corridor_centre(np.vstack([wall(1.2), clutter])) is None


def test_an_estimate_off_the_corridor_is_snapped_onto_it(fig2_map):
    seg = fig2_map.segments[0]
    a, b = fig2_map.node_xy(seg.a), fig2_map.node_xy(seg.b)
    mid = (a + b) / 2
    normal = np.array([-math.sin(seg.heading), math.cos(seg.heading)])
    off = mid + normal * (seg.width / 2 + 3.0)  # 3 m into the wall
    s = snap_to_corridor(fig2_map, Pose2D(*off, seg.heading), sigma=2.0)
    loc = fig2_map.locate(s.pose.x, s.pose.y)
    assert loc.offset < seg.width / 2
    assert s.moved > 3.0
    inside = snap_to_corridor(fig2_map, Pose2D(*mid, seg.heading), sigma=1.0)
    assert inside.moved == 0.0
    with pytest.raises(OffMapError, match="uncertainty"):
        snap_to_corridor(fig2_map, Pose2D(*(mid + normal * 40.0), seg.heading), sigma=0.5)
