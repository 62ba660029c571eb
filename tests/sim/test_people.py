"""Walking people: they walk with the clock at their speed, some pause, they keep off the
robot (stopping, then turning back) and do not step into the way ahead of a moving one
(crossing at a junction) nor freeze in it (walking ahead of it), the robot that drives
into one is stopped and the contact counted, the camera sees them where they are, and a
seed replays the crowd."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pytest

from pmnav_bt.config import WorldConfig
from pmnav_bt.seams import CameraIntrinsics, MotionStatus, Pose2D
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.render import PERSON_COLOUR, draw_top_down, render_camera
from pmnav_bt.sim.robot import COLLISION_HEIGHT, SimBase
from pmnav_bt.sim.scene.people import (
    KEEP_OFF_M,
    PAUSE_S,
    PERSON,
    PERSON_RADIUS_M,
    START_CLEAR_M,
    TURN_BACK_S,
    WALK_S,
    YIELD_AHEAD_M,
)
from pmnav_bt.sim.world import SimWorld

BUILDING = "straight_office"  # one corridor along x from 0 to 54 m, 2.2 m wide
K = CameraIntrinsics.from_hfov(160, 120, math.radians(60.0))


def crowd_config(**knobs) -> WorldConfig:
    base = dict(preset="realistic", clutter_per_10m=0.0, people_per_100m=12.0)
    return WorldConfig(**{**base, **knobs})


@dataclass
class FarAway:
    """A robot outside the building: the crowd follows its clock and never meets it."""

    clock: SimClock = field(default_factory=SimClock)
    radius: float = 0.17

    def pose(self) -> Pose2D:
        return Pose2D(1000.0, 1000.0, 0.0)


def _gaps(world: SimWorld, body: SimBase) -> list[float]:
    r = body.pose()
    return [
        math.hypot(q.x - r.x, q.y - r.y) - PERSON_RADIUS_M - body.radius
        for q in world.people.people
    ]


def test_people_walk_with_the_clock_at_their_speed():
    with SimWorld(BUILDING, scene=crowd_config(people_pausing=0.0), seed=1) as w:
        people = w.people.people
        expected = 54.0 * 12.0 / 100.0
        assert math.floor(expected) <= len(people) <= math.ceil(expected)
        lo, hi = w.scene.people_speed
        assert all(lo <= q.speed <= hi for q in people)
        robot = FarAway()
        w.people.attach(robot)
        before = w.people.poses()
        robot.clock.wait(5.0)
        for q, p0 in zip(people, before, strict=True):
            assert q.walked == pytest.approx(5.0 * q.speed, rel=1e-9)
            moved = math.hypot(q.x - p0.x, q.y - p0.y)
            assert 0.5 * q.speed * 5.0 < moved <= q.speed * 5.0 + 0.05  # turns at the ends
        w.people.detach(robot)
        robot.clock.wait(1.0)  # detached: the crowd no longer follows this clock
        assert [q.walked for q in people] == pytest.approx([5.0 * q.speed for q in people])


def test_pausing_people_stop_now_and_then_and_stand_still_meanwhile():
    with SimWorld(BUILDING, scene=crowd_config(people_pausing=1.0), seed=2) as w:
        robot = FarAway()
        w.people.attach(robot)
        t = WALK_S[1] + PAUSE_S[0] + 5.0  # every one has paused at least once by then
        still = 0
        for _ in range(int(t / 0.5)):
            standing = {id(q): (q.x, q.y) for q in w.people.people if q.pause_left > 0.5}
            robot.clock.wait(0.5)
            for q in w.people.people:
                if id(q) in standing:
                    assert (q.x, q.y) == standing[id(q)]
                    still += 1
        assert still
        for q in w.people.people:
            assert WALK_S[0] * q.speed <= q.walked <= (t - PAUSE_S[0]) * q.speed + 1e-6


def test_people_start_clear_of_the_robot_and_are_not_part_of_the_building():
    with SimWorld(BUILDING, scene=crowd_config(people_per_100m=40.0), seed=3) as w:
        body = SimBase(w, SimClock(), pose=Pose2D(20.0, 0.0, 0.0), width=16, height=12)
        assert min(_gaps(w, body)) >= START_CLEAR_M
        with SimWorld(BUILDING, scene=crowd_config(people_per_100m=0.0), seed=3) as empty:
            assert empty.people.people == []
            assert len(w.obstacle_footprints(COLLISION_HEIGHT)) == len(
                empty.obstacle_footprints(COLLISION_HEIGHT)
            )
        body.close()


def _ahead_of(world: SimWorld, distance: float):
    """A walking person with ``distance`` m and more of corridor ahead, and the pose
    ``distance`` m ahead of them in their lane, facing them."""
    for q in world.people.people:
        ahead = (54.0 - q.x) if abs(q.yaw) < 0.1 else q.x
        if ahead > distance + 2.0 and q.pause_left == 0.0:
            u = (math.cos(q.yaw), math.sin(q.yaw))
            return q, Pose2D(q.x + distance * u[0], q.y + distance * u[1], q.yaw + math.pi)
    raise AssertionError("no person with room ahead")


def test_a_person_stops_before_the_robot_then_turns_back_and_never_walks_into_it():
    with SimWorld(BUILDING, scene=crowd_config(people_pausing=0.0), seed=4) as w:
        body = SimBase(w, SimClock(), pose=Pose2D(0.5, 0.0, 0.0), width=16, height=12)
        q, there = _ahead_of(w, 2.5)
        body.set_pose(there)
        heading = q.yaw
        lows: list[float] = []
        body.clock.add_listener(lambda h: lows.append(min(_gaps(w, body))))
        gap_q = []
        body.clock.add_listener(
            lambda h: gap_q.append(math.hypot(q.x - there.x, q.y - there.y) - 0.42)
        )
        body.clock.wait(2.0)
        held = gap_q[-1]
        assert YIELD_AHEAD_M - 0.1 < held <= YIELD_AHEAD_M  # stopped short of the robot
        body.clock.wait(TURN_BACK_S + 3.0)
        assert math.cos(q.yaw - heading) < -0.99  # turned back ...
        assert gap_q[-1] > held + 2.0  # ... and walked away
        assert min(lows) >= KEEP_OFF_M - 1e-9
        assert w.people.contacts == 0 and body.stats.collisions == 0
        body.close()


def _one_person(w: SimWorld):
    """The crowd's first person alone in the world (the others moved out of it)."""
    from pmnav_bt.sim._pybullet import p

    crowd = w.people
    for o in crowd.people[1:]:
        p.resetBasePositionAndOrientation(
            o.body, (500.0, 500.0, -10.0), (0.0, 0.0, 0.0, 1.0), physicsClientId=w.client
        )
    crowd.people = crowd.people[:1]
    return crowd.people[0]


@pytest.mark.parametrize("start_s", [10.0, 10.5])
def test_a_person_crossing_waits_beside_the_way_of_a_moving_robot(start_s):
    # t_school: the stem (x = 0, y from -20 to 0) meets the bar (y = 0) at branch1 (0, 0).
    # The robot drives up the stem across the bar at full speed, never stopping; a person
    # walks along the bar towards the crossing, timed to reach it as the robot does. Seen
    # only where they stand, they would walk on into the robot's way and stop in front of
    # it (the robot then runs into them); seeing it move, they wait beside its way (and
    # turn back after a while, as for a robot standing in their way).
    with SimWorld("t_school", scene=crowd_config(people_pausing=0.0), seed=1) as w:
        q = _one_person(w)
        body = SimBase(w, SimClock(), pose=Pose2D(0.0, -3.0, math.pi / 2), width=16, height=12)
        q.corridor, q.forward, q.s, q.speed = 3, False, start_s, 1.2  # walking -x to (0, 0)
        q.lateral = w.people.lane(q)
        w.people._locate(q)
        lows: list[float] = []
        body.clock.add_listener(lambda h: lows.append(min(_gaps(w, body))))
        body.set_velocity(0.306, 0.0)
        body.clock.wait(12.0)  # 3.7 m: across the bar and up to its far wall
        assert w.people.contacts == 0 and body.stats.collisions == 0
        assert KEEP_OFF_M - 1e-9 <= min(lows) < 0.5  # they met, and the person kept off
        body.close()


def test_a_person_walking_ahead_of_a_moving_robot_walks_on_where_their_lane_narrows():
    # t_school's bar, towards branch2 (24, 0): the keep-right lane tapers to the centre line
    # there. A person just ahead of the robot, beside its way, steps towards its way as
    # they walk; stopping there (in front of it, out of its camera's view) would have it
    # run into them from behind. They walk on.
    with SimWorld("t_school", scene=crowd_config(people_pausing=0.0), seed=1) as w:
        q = _one_person(w)
        body = SimBase(w, SimClock(), pose=Pose2D(22.3, 0.0, 0.0), width=16, height=12)
        q.corridor, q.forward, q.s, q.speed = 3, True, 22.8, 1.2  # walking +x to (24, 0)
        q.lateral = w.people.lane(q)
        w.people._locate(q)
        body.set_velocity(0.306, 0.0)
        body.clock.wait(4.0)
        assert w.people.contacts == 0 and body.stats.collisions == 0
        assert q.walked > 3.0  # on their way, not held up
        body.close()


def test_the_robot_driving_into_a_standing_person_is_stopped_and_the_contact_counted():
    with SimWorld(BUILDING, scene=crowd_config(people_pausing=0.0), seed=5) as w:
        body = SimBase(w, SimClock(), pose=Pose2D(0.5, 0.0, 0.0), width=16, height=12)
        q, there = _ahead_of(w, 1.5)
        q.pause_left = 60.0  # standing, facing away from the robot behind them
        behind = Pose2D(q.x - 1.5 * math.cos(q.yaw), q.y - 1.5 * math.sin(q.yaw), q.yaw)
        body.set_pose(behind)
        body.set_velocity(0.3, 0.0)
        body.clock.wait(5.0)
        assert body.motion_status() == MotionStatus.BLOCKED
        assert body.stats.collisions == 1 and w.people.contacts == 1
        assert min(_gaps(w, body)) == pytest.approx(0.0, abs=1e-3)
        body.close()


def test_the_camera_and_the_plan_show_people_where_they_are_now():
    with SimWorld(BUILDING, scene=crowd_config(people_pausing=0.0), seed=6) as w:
        robot = FarAway()
        w.people.attach(robot)
        robot.clock.wait(2.0)
        person = w.label_id(PERSON)
        for q in w.people.people:
            back = -1.0 if 2.0 < q.x - 2.5 * math.cos(q.yaw) < 53.0 else 1.0  # in the corridor
            eye = (q.x + back * 2.5 * math.cos(q.yaw), q.y + back * 2.5 * math.sin(q.yaw))
            f = render_camera(w, *eye, math.atan2(q.y - eye[1], q.x - eye[0]), K, height=1.2)
            assert (f.segmentation[55:65, 75:85] == person).mean() > 0.5
        img = draw_top_down(w, px_per_m=20.0, margin_m=3.0)
        x0, _, _, y1 = w.bounds(margin=3.0)
        for q in w.people.people:
            u, v = int(round((q.x - x0) * 20)), int(round((y1 - q.y) * 20))
            assert tuple(img[v - 3, u]) == PERSON_COLOUR or tuple(img[v + 3, u]) == PERSON_COLOUR


def _crowd_after(seed: int, seconds: float) -> list[tuple[float, float]]:
    with SimWorld("fig2_hospital", scene=crowd_config(people_pausing=0.5), seed=seed) as w:
        body = SimBase(w, SimClock(), width=16, height=12)
        body.set_velocity(0.3, 0.0)
        body.clock.wait(seconds)
        out = [(round(q.x, 9), round(q.y, 9)) for q in w.people.people]
        body.close()
        return out


def test_a_seed_replays_the_crowd():
    a = _crowd_after(7, 20.0)
    assert a == _crowd_after(7, 20.0)
    assert a != _crowd_after(8, 20.0)
    assert np.isfinite(np.array(a)).all()


def test_the_clean_preset_has_nobody_and_leaves_the_clock_to_the_robot():
    with SimWorld(BUILDING) as w:
        body = SimBase(w, SimClock(), width=16, height=12)
        assert w.people.people == []
        assert body.clock._listeners == [body._advance]
        assert w.people.clearance(0.0, 0.0, 0.17) == math.inf
        body.close()
