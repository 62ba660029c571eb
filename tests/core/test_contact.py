"""After a touch: where the contact is, backing off away from it (not into what is known
behind), the item a bump implies, and the step aside round it."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.contact import (
    BACK_OFF_M,
    ITEM_RADIUS_M,
    WAY_PAD_M,
    BackOff,
    felt_contact,
    felt_item,
    round_contact,
    way_clear,
)
from pmnav_bt.hazards import HazardKind, place
from pmnav_bt.seams import CREATE3_RADIUS_M, Pose2D


def nothing(x: float, y: float) -> float:
    return math.inf


def marks(*points):
    """A clearance function of a few marked points (a costmap's, in miniature)."""
    return lambda x, y: min(math.dist((x, y), p) for p in points)


class _Body:
    def __init__(self, pose, bump=None):
        self._pose, self._bump = pose, bump

    def pose(self):
        return self._pose

    def hazards(self, since=-math.inf):
        return [self._bump] if self._bump else []

    def blocked_by(self):
        return self._bump


def test_the_contact_is_the_bump_felt_else_the_rim_ahead():
    pose = Pose2D(1.0, 2.0, math.pi / 2)
    bump = place(HazardKind.BUMP, "bump_left", pose, 3.0)
    c = felt_contact(_Body(pose, bump), 3.0)
    assert c.point == bump.point and c.words.startswith("bumped left at")
    c = felt_contact(_Body(pose), 3.0)  # no bumper: it drove into what it touched
    assert c.point == pytest.approx((1.0, 2.0 + CREATE3_RADIUS_M))


def run(backoff, pose, blocked=lambda p: False, ticks=200, dt=0.1):
    """Integrate the back-off's commands on a kinematic body; the final pose."""
    for i in range(ticks):
        v, w, done = backoff.command(pose, blocked(pose), i * dt)
        if done:
            return pose
        yaw = pose.yaw + w * dt
        pose = Pose2D(pose.x + v * dt * math.cos(yaw), pose.y + v * dt * math.sin(yaw), yaw)
    raise AssertionError("the back-off never ended")


def test_backing_off_turns_to_face_a_side_contact_then_reverses_straight_away_from_it():
    start = Pose2D(0.0, 0.0, 0.0)
    contact = (0.0, CREATE3_RADIUS_M)  # on the left side
    end = run(BackOff(contact, start, 0.0), start)
    assert math.dist((end.x, end.y), contact) == pytest.approx(
        CREATE3_RADIUS_M + BACK_OFF_M, abs=0.02
    )
    assert end.y < -BACK_OFF_M + 0.02  # straight away from it: south, not back along x


def test_backing_off_stops_where_the_body_refuses_and_never_into_what_is_behind():
    start = Pose2D(0.0, 0.0, 0.0)
    ahead = (CREATE3_RADIUS_M, 0.0)
    refused = BackOff(ahead, start, 0.0)
    end = run(refused, start, blocked=lambda p: p.x < -0.05)  # the backup buffer ends
    assert -0.07 < end.x < -0.04 and refused.why == "the body would reverse no further"
    box = marks((-0.3, 0.0))  # a box 0.3 m behind: it reverses, short of its margin
    end = run(BackOff(ahead, start, 0.0, clearance=box), start)
    assert end.x < -0.03
    assert CREATE3_RADIUS_M + WAY_PAD_M <= box(end.x, end.y) < CREATE3_RADIUS_M + 0.1
    boxed = BackOff(ahead, start, 0.0, clearance=marks((-0.2, 0.0)))  # no room at all
    assert run(boxed, start) == start and boxed.why == "something behind"


def test_the_item_felt_ahead_and_marked_does_not_hold_the_body_that_backs_off_it():
    """The costmap holds the item the body touched (``felt_item``, at its rim): reversing
    straight away from it is free, and something behind still stops it short."""
    start = Pose2D(0.0, 0.0, 0.0)
    ahead = (CREATE3_RADIUS_M, 0.0)
    touched = marks(*felt_item(start, ahead))
    backed = BackOff(ahead, start, 0.0, clearance=touched)
    end = run(backed, start)
    assert end.x == pytest.approx(-BACK_OFF_M, abs=0.02) and backed.why == ""
    both = marks(*felt_item(start, ahead), (-0.3, 0.0))
    end = run(BackOff(ahead, start, 0.0, clearance=both), start)
    assert -BACK_OFF_M + 0.02 < end.x < -0.03
    assert both(end.x, end.y) >= CREATE3_RADIUS_M + WAY_PAD_M - 1e-9


def test_a_bump_marks_an_item_behind_the_contact_away_from_the_body():
    pose = Pose2D(0.0, 0.0, 0.0)
    pts = felt_item(pose, (CREATE3_RADIUS_M, 0.0))
    assert pts[0] == (CREATE3_RADIUS_M, 0.0)
    xs = [p[0] for p in pts]
    assert min(xs) >= CREATE3_RADIUS_M - 1e-9  # nothing on the body's side
    assert max(xs) == pytest.approx(CREATE3_RADIUS_M + 2 * ITEM_RADIUS_M)


def test_the_step_aside_goes_away_from_the_contact_and_clear_of_the_item():
    here = Pose2D(0.0, 0.0, 0.0)
    goal = (5.0, 0.0)
    contact = (0.25, 0.1)  # ahead, a little left: step right
    known = marks(*felt_item(here, contact))
    p = round_contact(here, contact, goal, known, lambda p: True)
    assert p is not None and p[1] < 0.0 and abs(p[0]) < 1e-9
    assert way_clear(p, (p[0] + 1.5, p[1]), known, skip=0.0)
    # The right side walled off (the map's corridor): the left one, wider round the item.
    p = round_contact(here, contact, goal, known, lambda p: p[1] > -0.2)
    assert p is not None and p[1] > 0.0
    assert round_contact(here, contact, (0.2, 0.0), known, lambda p: True) is None  # goal first
