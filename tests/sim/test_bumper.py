"""The simulated bumper: the zone a contact presses, from the body's clearance in the
pybullet world (fig2_hospital: the corridor at x = 47 runs along x, its north wall at
y = 21.2)."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.geometry import wrap_angle
from pmnav_bt.hazards import HazardKind
from pmnav_bt.seams import MotionStatus, Pose2D
from pmnav_bt.sim.bumper import contact_bearing, pressed_zone
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.odometry import NoisyOdometry
from pmnav_bt.sim.robot import COLLISION_HEIGHT, SimBase


@pytest.fixture(scope="module")
def at_the_wall(world):
    """Where a body driven north into the wall stops, touching it."""
    clock = SimClock()
    body = SimBase(world, clock, pose=Pose2D(47.0, 20.5, math.pi / 2), depth=False,
                   segmentation=False)  # fmt: skip
    body.set_velocity(0.3, 0.0)
    for _ in range(100):
        clock.wait(0.05)
        if body.motion_status() == MotionStatus.BLOCKED:
            break
    q = body.pose()
    body.close()
    assert q.y == pytest.approx(21.2 - body.radius, abs=0.01)
    return q, body.radius


@pytest.mark.parametrize(
    ("heading_deg", "zone"),
    [
        (90.0, "bump_front_center"),  # straight at it
        (90.0 - 36.0, "bump_front_left"),  # the wall 36 deg left of ahead
        (90.0 + 36.0, "bump_front_right"),
        (90.0 - 72.0, "bump_left"),
        (-90.0, None),  # backed into it: the Create 3 has no bumper behind
    ],
)
def test_the_zone_pressed_is_the_one_towards_the_contact(world, at_the_wall, heading_deg, zone):
    q, radius = at_the_wall
    pose = Pose2D(q.x, q.y, math.radians(heading_deg))
    bearing = contact_bearing(world, pose, radius, COLLISION_HEIGHT)
    assert abs(wrap_angle(bearing - math.radians(90.0 - heading_deg))) < math.radians(2)
    assert pressed_zone(world, pose, radius, COLLISION_HEIGHT, 0.2) == zone


def test_the_bumper_is_pressed_only_driving_into_what_it_touches(world, at_the_wall):
    q, radius = at_the_wall
    h = COLLISION_HEIGHT
    assert pressed_zone(world, q, radius, h, 0.0) is None  # at rest, or turning on the spot
    assert pressed_zone(world, q, radius, h, -0.1) is None  # backing off
    for deg in (0.0, -10.0):  # turned along the wall, or a little away from it
        along = Pose2D(q.x, q.y, math.radians(deg))
        assert contact_bearing(world, along, radius, COLLISION_HEIGHT) is not None
        assert pressed_zone(world, along, radius, COLLISION_HEIGHT, 0.2) is None
    into = Pose2D(q.x, q.y, math.radians(10.0))  # a little into it: the side zone
    assert pressed_zone(world, into, radius, COLLISION_HEIGHT, 0.2) == "bump_left"


def test_a_body_a_centimetre_clear_touches_nothing(world, at_the_wall):
    q, radius = at_the_wall
    assert contact_bearing(world, Pose2D(q.x, q.y - 0.01, q.yaw), radius, COLLISION_HEIGHT) is None


def test_the_body_feels_what_cut_its_motion_until_it_moves_again(world):
    """``SimBase`` is a body with a bumper: driven at the wall 36 deg off square, the cut
    motion is one bump, front right, on its rim (odometry; through drifting odometry in
    that frame); a new motion lets go of it, and backing off feels nothing."""
    clock = SimClock()
    start = Pose2D(47.0, 20.7, math.radians(90.0 + 36.0))
    body = SimBase(world, clock, pose=start, depth=False, segmentation=False)
    try:
        body.set_velocity(0.3, 0.0)
        for _ in range(100):
            clock.wait(0.05)
            if body.motion_status() == MotionStatus.BLOCKED:
                break
        (bump,) = body.hazards()
        assert bump.kind == HazardKind.BUMP and bump.frame == "bump_front_right"
        q = body.pose()
        assert math.dist(bump.point, (q.x, q.y)) == pytest.approx(body.radius)
        assert body.blocked_by() == bump
        assert body.hazards(since=bump.stamp + 0.01) == []
        body.set_velocity(0.3, 0.0)  # pushing on: the same bump, not another
        clock.wait(0.05)
        assert body.hazards() == [bump]
        assert (body.blocked_by().frame, body.blocked_by().point) == (bump.frame, bump.point)
        body.set_velocity(-0.1, 0.0)
        clock.wait(0.5)
        assert body.blocked_by() is None and body.hazards() == [bump]
    finally:
        body.close()
    drifting = NoisyOdometry(SimBase(world, SimClock(), pose=start, depth=False,
                                     segmentation=False), noise=0.05, seed=3)  # fmt: skip
    try:
        drifting.set_velocity(0.3, 0.0)
        for _ in range(100):
            drifting.clock.wait(0.05)
            if drifting.motion_status() == MotionStatus.BLOCKED:
                break
        (bump,) = drifting.hazards()
        o = drifting.pose()  # the point is where the drifting frame has the body's rim
        assert math.dist(bump.point, (o.x, o.y)) == pytest.approx(drifting.inner.radius)
        assert drifting.blocked_by() == bump
    finally:
        drifting.inner.close()
