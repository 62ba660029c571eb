"""The Create 3's hazards without ROS: bumper zones, where each sensor's hazard lies in the
odometry frame, its words, the motions a hazard forbids (``HazardWatch``), and the
calibrated odometry carrying hazards into its own frame."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.hardware.hazards import (
    BUMP_HOLD_S,
    FAULT_HOLD_S,
    STALL_GRACE_S,
    HazardWatch,
)
from pmnav_bt.hazards import (
    Hazard,
    HazardKind,
    body_blocked_by,
    body_hazards,
    bump_zone,
    place,
    sensor,
)
from pmnav_bt.pose.odometry import CalibratedBase
from pmnav_bt.seams import CREATE3_RADIUS_M, Pose2D
from pmnav_bt.testing.doubles import FakeBase


@pytest.mark.parametrize(
    ("deg", "zone"),
    [
        (0.0, "bump_front_center"),
        (17.0, "bump_front_center"),
        (19.0, "bump_front_left"),
        (53.0, "bump_front_left"),
        (55.0, "bump_left"),
        (90.0, "bump_left"),
        (-30.0, "bump_front_right"),
        (-80.0, "bump_right"),
        (91.0, None),
        (180.0, None),
        (-100.0, None),
        (360.0 + 40.0, "bump_front_left"),  # wrapped
    ],
)
def test_a_contact_presses_the_zone_of_its_bearing_and_none_behind(deg, zone):
    assert bump_zone(math.radians(deg)) == zone


def test_a_bump_lies_on_the_rim_at_its_zone_and_turns_with_the_body():
    h = place(HazardKind.BUMP, "bump_front_left", Pose2D(2.0, 1.0, math.pi / 2), 5.0)
    # facing +y, the front-left zone (36 deg left of ahead) is up and to the left
    r = CREATE3_RADIUS_M
    assert h.point == pytest.approx(
        (2.0 - r * math.sin(math.radians(36)), 1.0 + r * math.cos(math.radians(36)))
    )
    assert h.stamp == 5.0 and h.side == "front left"
    assert h.describe() == f"bumped front left at ({h.point[0]:.2f}, {h.point[1]:.2f})"


def test_sensor_frames_name_their_side_and_unknown_ones_the_centre():
    assert sensor("robot1/cliff_side_right").offset == (0.06, -0.145)  # namespaced
    assert sensor("bump_front_center").side == "front"
    unknown = place(HazardKind.BUMP, "bumper_x", Pose2D(1.0, 2.0, 0.3), 0.0)
    assert unknown.point == (1.0, 2.0) and unknown.describe() == "bumped at (1.00, 2.00)"
    cliff = place(HazardKind.CLIFF, "cliff_front_right", Pose2D(0.0, 0.0, 0.0), 0.0)
    assert cliff.describe() == "cliff front right at (0.16, -0.04)"
    stall = place(HazardKind.STALL, "left_wheel", Pose2D(0.0, 0.0, 0.0), 0.0)
    assert stall.describe() == "left wheel stalled at (0.00, 0.12)"
    drop = place(HazardKind.WHEEL_DROP, "wheel_drop_right", Pose2D(0.0, 0.0, 0.0), 0.0)
    assert drop.describe() == "right wheel dropped at (0.00, -0.12)"


def test_a_hazard_moves_into_another_frame():
    h = Hazard(HazardKind.BUMP, "bump_left", (1.0, 0.0), 0.0)
    assert h.moved((0.0, 1.0, math.pi / 2)).point == pytest.approx((0.0, 2.0))


def _bump(frame="bump_front_center", x=1.0, t=0.0):
    return Hazard(HazardKind.BUMP, frame, (x, 0.0), t)


def test_a_pressed_bumper_forbids_driving_forwards_only_while_it_is_felt():
    w = HazardWatch()
    w.feel(_bump(), now=10.0)
    assert w.forbids(0.2, 0.0, 10.1, 0.0) == _bump()
    assert w.forbids(0.2, 0.5, 10.1, 2.0) == _bump()  # an arc forwards too
    assert w.forbids(-0.1, 0.0, 10.1, 0.0) is None  # backing off the wall
    assert w.forbids(0.0, 1.0, 10.1, 0.0) is None  # turning on the spot
    assert w.forbids(0.2, 0.0, 10.0 + BUMP_HOLD_S + 0.01, 0.0) is None  # released
    assert w.fault(10.1) is None


def test_a_stall_stops_only_a_motion_that_had_time_to_turn_the_wheels():
    w = HazardWatch()
    w.feel(Hazard(HazardKind.STALL, "left_wheel", (0.0, 0.1), 0.0), now=5.0)
    assert w.forbids(-0.1, 0.0, 5.05, 0.0) is None  # a new command may try again
    assert w.forbids(-0.1, 0.0, 5.05, STALL_GRACE_S - 0.01) is None
    assert w.forbids(-0.1, 0.0, 5.05, STALL_GRACE_S).kind == HazardKind.STALL
    # a stall felt before this motion began is not this motion's
    assert w.forbids(-0.1, 0.0, 5.0 + STALL_GRACE_S + 0.1, STALL_GRACE_S) is None


def test_a_cliff_forbids_every_motion_and_faults_for_a_while():
    w = HazardWatch()
    cliff = Hazard(HazardKind.CLIFF, "cliff_front_left", (0.2, 0.0), 0.0)
    w.feel(cliff, now=1.0)
    for v, wz in ((0.1, 0.0), (-0.1, 0.0), (0.0, -1.0)):
        assert w.forbids(v, wz, 1.5, 0.0) == cliff
    assert w.forbids(0.0, 0.0, 1.5, 0.0) is None  # standing still is allowed
    assert w.fault(1.0 + FAULT_HOLD_S) == cliff
    assert w.fault(1.0 + FAULT_HOLD_S + 0.01) is None


def test_a_hazard_felt_again_in_the_same_place_is_kept_once_with_its_newest_stamp():
    w = HazardWatch()
    for i in range(10):  # the robot repeats a pressed bumper at ~60 Hz
        w.feel(_bump(x=1.0 + 0.001 * i, t=float(i)), now=float(i))
    w.feel(_bump("bump_left", t=10.0), now=10.0)
    w.feel(_bump(x=2.0, t=11.0), now=11.0)  # the same zone elsewhere: another place
    felt = w.felt()
    assert [(h.frame, h.stamp) for h in felt] == [
        ("bump_front_center", 9.0), ("bump_left", 10.0), ("bump_front_center", 11.0)
    ]  # fmt: skip
    assert [h.stamp for h in w.felt(since=10.0)] == [10.0, 11.0]


class _Feeling(FakeBase):
    """A double with hazard sensors: a bump felt at (1, 0) of its odometry."""

    def hazards(self, since=-math.inf):
        return [h for h in [_bump(t=3.0)] if h.stamp >= since]

    def blocked_by(self):
        return _bump(t=3.0)


def test_calibrated_odometry_puts_the_body_s_hazards_in_its_own_frame():
    body = _Feeling()
    cal = CalibratedBase(body)
    assert body_hazards(cal) == [_bump(t=3.0)]  # not calibrated: the frames agree
    assert body_hazards(cal, since=3.5) == []
    cal.pose()
    cal.gain = 1.1  # turning measured 10 % short
    body.set_velocity(0.0, 1.0)
    body.clock.wait(1.0)
    moved = body_hazards(cal)[0]
    corr_T_raw = cal.corr_T_raw()
    assert corr_T_raw[2] == pytest.approx(0.1, abs=1e-3)
    assert moved.point == pytest.approx(_bump().moved(corr_T_raw).point)
    assert moved.point != pytest.approx(_bump().point)
    assert body_blocked_by(cal).point == moved.point
    # A body without hazard sensors felt nothing.
    plain = CalibratedBase(FakeBase())
    assert body_hazards(plain) == [] and body_blocked_by(plain) is None
