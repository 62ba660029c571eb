"""The odometry's rotation scale, measured from the walls during a panorama, and its
distance scale, measured from a wall ahead while driving straight, taken out."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.geometry import wrap_angle
from pmnav_bt.pose.odometry import CalibratedBase, distance_scale, rotation_scale_error
from pmnav_bt.seams import Pose2D

AXIS = math.radians(7.0)  # the corridor's axis in the map (walls along and across it)


def panorama(scale: float, n: int = 6, start: float = 0.3, noise=()) -> list:
    """The views of a panorama on odometry that turns ``scale`` times the true rotation:
    (odometry yaw, wall direction seen in the view, inliers), every 60 deg of odometry."""
    views = []
    for i in range(n):
        odom = start + math.radians(30.0 + 60.0 * i)
        true = start + (odom - start) / scale
        a = wrap_angle(2.0 * (AXIS - true)) / 2.0  # the wall along the axis, in the view
        if i % 2:  # some views see the wall across the corridor
            a = wrap_angle(2.0 * (AXIS + math.pi / 2 - true)) / 2.0
        a += noise[i] if noise else 0.0
        views.append((wrap_angle(odom), a, 200))
    return views


@pytest.mark.parametrize("scale", [0.93, 1.0, 1.05, 1.08])
def test_the_walls_measure_how_much_the_odometry_over_or_under_turns(scale):
    err = rotation_scale_error(panorama(scale))
    assert err == pytest.approx(1.0 - 1.0 / scale, abs=1e-6)


def test_a_few_degrees_of_wall_noise_leave_the_error_within_a_percent():
    noise = [math.radians(d) for d in (1.0, -1.0, 0.5, -0.5, 1.0, -1.0)]
    err = rotation_scale_error(panorama(1.05, noise=noise))
    assert err == pytest.approx(1.0 - 1.0 / 1.05, abs=0.01)


def test_too_few_views_or_walls_that_fit_no_axis_measure_nothing():
    assert rotation_scale_error(panorama(1.05, n=3)) is None
    noise = [math.radians(d) for d in (0.0, 20.0, -15.0, 0.0, 25.0, 0.0)]  # other walls
    assert rotation_scale_error(panorama(1.05, noise=noise)) is None


class TurnOnly:
    """A base whose odometry turns ``scale`` times the true rotation (no other error)."""

    def __init__(self, scale: float):
        self.scale = scale
        self.clock = None
        self.true = Pose2D(0.0, 0.0, 0.0)
        self.odom = Pose2D(0.0, 0.0, 0.0)

    def turn(self, true_angle: float) -> None:
        self.true = Pose2D(self.true.x, self.true.y, self.true.yaw + true_angle)
        self.odom = Pose2D(
            self.odom.x, self.odom.y, wrap_angle(self.odom.yaw + true_angle * self.scale)
        )

    def forward(self, d: float) -> None:
        t, o = self.true, self.odom
        self.true = Pose2D(t.x + d * math.cos(t.yaw), t.y + d * math.sin(t.yaw), t.yaw)
        self.odom = Pose2D(o.x + d * math.cos(o.yaw), o.y + d * math.sin(o.yaw), o.yaw)

    def pose(self) -> Pose2D:
        return self.odom


def _turn_in_steps(base: TurnOnly, cal: CalibratedBase, angle: float, steps: int = 12) -> None:
    for _ in range(steps):
        base.turn(angle / steps)
        cal.pose()  # the tree reads the pose every tick


def test_calibrated_odometry_turns_round_true_and_drives_where_the_robot_drives():
    base = TurnOnly(1.08)
    cal = CalibratedBase(base)
    _turn_in_steps(base, cal, math.pi)
    assert cal.pose() == base.pose()  # not calibrated: the odometry as it is
    for _ in range(4):  # one panorama each: the error the walls measure on `cal`
        cal.calibrate(1.0 - 1.0 / (base.scale * cal.gain))
    assert cal.gain == pytest.approx(1.0 / 1.08, rel=0.01)
    yaw0 = cal.pose().yaw
    _turn_in_steps(base, cal, math.pi)  # turn round
    raw_error = abs(wrap_angle(base.pose().yaw - yaw0 - math.pi))
    assert math.degrees(raw_error) > 14.0  # the odometry alone is 14 deg off
    assert abs(wrap_angle(cal.pose().yaw - yaw0 - math.pi)) < math.radians(1.0)
    before = cal.pose()
    base.forward(2.0)
    after = cal.pose()
    assert math.dist((before.x, before.y), (after.x, after.y)) == pytest.approx(2.0)
    assert math.atan2(after.y - before.y, after.x - before.x) == pytest.approx(after.yaw)


def approach(scale: float, start: float = 9.0, odom_step: float = 0.3, n: int = 20) -> list:
    """A straight drive at a wall ``start`` m ahead on odometry that counts ``scale``
    times the true distance: (odometry distance, free floor ahead) every ``odom_step``."""
    return [(i * odom_step, start - i * odom_step / scale) for i in range(n)]


@pytest.mark.parametrize("scale", [0.9, 1.0, 1.07])
def test_a_wall_ahead_measures_how_far_the_odometry_over_or_under_counts(scale):
    # Readings beyond 6 m (the wall's foot a pixel or two tall) are left out.
    assert distance_scale(approach(scale)) == pytest.approx(1.0 / scale, abs=1e-9)


def test_the_longest_run_of_readings_of_one_wall_counts():
    track = approach(1.07, start=6.0, n=14)
    track[4] = (track[4][0], 1.5)  # a door frame stood out for one frame
    # ... and the wall beyond came into view after a side corridor opened: another run
    track += [(4.2 + 0.3 * i, 5.5 - 0.3 * i / 1.07) for i in range(5)]
    assert distance_scale(track) == pytest.approx(1.0 / 1.07, abs=1e-9)


def test_too_short_a_drive_or_readings_that_fit_no_approach_measure_nothing():
    assert distance_scale(approach(1.07, start=5.0, n=6)) is None  # 1.5 m of driving
    wobbly = [(s, f + (0.12 if i % 2 else -0.12)) for i, (s, f) in enumerate(approach(1.0, 6.0))]
    assert distance_scale(wobbly) is None
    assert distance_scale(approach(1.4, start=6.0)) is None  # beyond any wheel's error
    assert distance_scale([]) is None
