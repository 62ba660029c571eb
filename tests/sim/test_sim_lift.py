"""The simulator's lift: a cabin behind the lift's doors on each level, doors that open
when it comes, a cart in a cabin that comes full, and one ride of the lift subtree from
level to level world (issue 40)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from blackboard_kit import writer
from building_kit import as_floor
from py_trees.common import Status

from pmnav_bt.behaviours.lift import (
    DOORS_ASIDE,
    Ride,
    doors_along,
    look_into_cabin,
    opening_samples,
)
from pmnav_bt.config import load_config
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.lift_doorway import DOORWAY_WALL_M, doorway
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.seams import LiftDoor, MotionStatus, Pose2D
from pmnav_bt.sim.levels import LevelBody
from pmnav_bt.sim.lift import SimLift
from pmnav_bt.sim.scene.appearance import WALL_THICKNESS
from pmnav_bt.sim.world import SimWorld
from pmnav_bt.testing.oracle import ORACLE
from pmnav_bt.trees.lift import level_context, lift_subtree
from pmnav_bt.trees.runner import make_context

pytestmark = pytest.mark.world

PERIOD = 0.1


@pytest.fixture(scope="module")
def levels():
    office = load_building("straight_office")
    return {"L3": office, "L4": as_floor(office, 4)}


@pytest.fixture(scope="module")
def worlds(levels):
    made = {name: SimWorld(b, lifts={"elevator1"}) for name, b in levels.items()}
    yield made
    for w in made.values():
        w.close()


def test_the_map_doorway_is_where_the_world_cut_it(worlds, levels):
    assert DOORWAY_WALL_M == WALL_THICKNESS
    cabin = worlds["L3"].cabins["elevator1"]
    d = doorway(parse_building(levels["L3"]), "elevator1")
    assert math.dist(cabin.centre, d.centre) < 0.01 and np.allclose(cabin.into, d.into)


def test_a_world_without_lifts_has_no_cabin_and_an_unknown_lift_is_refused(levels):
    with SimWorld(levels["L3"]) as w:
        assert w.cabins == {}
    with pytest.raises(Exception, match="no lift landmark 'stairs1'"):
        SimWorld(levels["L3"], lifts={"stairs1"})


def test_depth_sees_shut_doors_an_open_cabin_a_full_one_and_the_way_in(worlds, levels):
    body = LevelBody(worlds, "L3", Pose2D(0.0, 0.0, 0.0), width=160, height=120)
    cabin = worlds["L3"].cabins["elevator1"]
    try:
        d = doorway(parse_building(levels["L3"]), "elevator1")

        def look(off: float = 0.0):
            """From the lobby ``off`` m along the corridor, facing the doors, the robot
            believing it is at the lobby itself."""
            at = Pose2D(d.lobby[0] + off, d.lobby[1], d.yaw_in)
            body.carry("L3", at)
            return look_into_cabin(body.observe(), Pose2D(*d.lobby, d.yaw_in), d)

        shut = look()
        assert shut.way is None and not shut.beyond  # the doors: no doorway in view
        cabin.set_door(True)
        straight = look()
        assert straight.way is not None and abs(straight.way[0]) < math.radians(5)
        assert straight.way[1] == pytest.approx(math.dist(d.lobby, d.cabin_centre()), abs=0.05)
        aside = look(off=-0.6)  # 0.6 m west of where it believes: the way in is to its right
        assert aside.way is not None and aside.way[0] < -math.radians(10)
        cabin.fill()
        full = look()
        assert full.way is None and full.beyond
        assert body.world.clearance(*cabin.middle, 0.17) < 0  # the cart stands there
        cabin.empty()
        assert body.world.clearance(*cabin.middle, 0.17) > 0  # room to stand in the cabin
    finally:
        cabin.set_door(False)
        cabin.empty()
        body.close()


@pytest.mark.parametrize("off", [-1.6, -0.8, 0.0, 1.4])
def test_the_open_doors_seen_aside_put_the_estimate_right_along_the_wall(worlds, levels, off):
    """The robot stands ``off`` m along the corridor from the lobby point, believing it is
    at the lobby point (the lift's plate, 1-2 m beside the doors, placed it): the doorway
    seen in depth, straight ahead and turned aside, says where along the wall it is."""
    body = LevelBody(worlds, "L3", Pose2D(0.0, 0.0, 0.0), width=160, height=120)
    cabin = worlds["L3"].cabins["elevator1"]
    d = doorway(parse_building(levels["L3"]), "elevator1")
    u = np.asarray(d.into)
    along = np.array([-u[1], u[0]])
    truly = np.asarray(d.lobby) + off * along

    def samples():
        out = []
        for turn in (0.0, DOORS_ASIDE, -DOORS_ASIDE):
            body.carry("L3", Pose2D(*truly, d.yaw_in + turn))
            out += opening_samples(body.observe(), Pose2D(*d.lobby, d.yaw_in + turn), d)
        return out

    try:
        assert doors_along(samples(), 0.0, d.width) is None  # shut: no doorway
        cabin.set_door(True)
        shift = doors_along(samples(), 0.0, d.width)
        assert shift is not None
        moved = np.asarray(d.lobby) - shift * along  # the estimate, put right
        assert np.linalg.norm(moved - truly) < 0.25
    finally:
        cabin.set_door(False)
        body.close()


def test_the_doorway_stays_open_under_the_realistic_walls(levels):
    cfg = load_config(overrides=["world.preset=realistic", "world.people_per_100m=0"])
    with SimWorld(levels["L3"], scene=cfg.world, seed=3, lifts={"elevator1"}) as w:
        d = doorway(parse_building(levels["L3"]), "elevator1")
        w.cabins["elevator1"].set_door(True)
        body = LevelBody({"L3": w}, "L3", Pose2D(*d.lobby, d.yaw_in), width=160, height=120)
        try:
            look = look_into_cabin(body.observe(), Pose2D(*d.lobby, d.yaw_in), d)
            assert look.way is not None
        finally:
            body.close()


def test_one_ride_takes_the_robot_in_on_one_level_and_out_on_the_next(worlds, levels):
    pm3, pm4 = parse_building(levels["L3"]), parse_building(levels["L4"])
    board, alight = doorway(pm3, "elevator1"), doorway(pm4, "elevator1")
    body = LevelBody(worlds, "L3", Pose2D(6.0, 0.2, math.pi), width=160, height=120)
    lift = SimLift(body.clock, body, worlds["L3"].rng("lift"))
    lift.add("lift_a", "Lift A", {n: w.cabins["elevator1"] for n, w in worlds.items()}, "L4")
    cfg = load_config(overrides=[ORACLE])
    ctx = make_context(body, pm3, cfg, deferred_work=True)
    try:
        ctx_to = level_context(ctx, pm4)
        bb = writer()
        bb.set("map_T_odom", (0.0, 0.0, 0.0))  # odometry starts in L3's map frame
        bb.set("goal", "room5")
        ride = Ride("lift_a", "Lift A", "L3", "L4", board, alight)
        tree = lift_subtree(ctx, ctx_to, lift, ride, levels)
        path: list[tuple[str, float, float]] = []
        for _ in range(6000):
            tree.tick_once()
            p = body.world_pose()
            path.append((body.level, p.x, p.y))
            if tree.status != Status.RUNNING:
                break
            ctx.worker.drain()
            body.clock.wait(PERIOD)
        failure = bb.get("failure") if bb.exists("failure") else None
        assert tree.status == Status.SUCCESS, failure
        assert body.level == "L4" and bb.get("level") == "L4"
        cabin3 = worlds["L3"].cabins["elevator1"]
        assert any(lv == "L3" and cabin3.holds(x, y) for lv, x, y in path)  # in on L3
        out = next(i for i, (lv, _, _) in enumerate(path) if lv == "L4")
        assert worlds["L4"].cabins["elevator1"].holds(*path[out][1:])  # arrived in the cabin
        x, y = path[-1][1:]
        assert math.dist((x, y), alight.lobby) < 1.0  # left it for the corridor of L4
        est, true = ctx.base.pose(), body.world_pose()
        tf = bb.get("map_T_odom")
        ex = tf[0] + math.cos(tf[2]) * est.x - math.sin(tf[2]) * est.y
        ey = tf[1] + math.sin(tf[2]) * est.x + math.cos(tf[2]) * est.y
        assert math.dist((ex, ey), (true.x, true.y)) < 0.5  # localized on L4's map
        assert lift.state("lift_a").session == "" and body.stats.collisions == 0
        st = lift.state("lift_a")
        assert st.current_level == "L4" and st.door in (LiftDoor.OPEN, LiftDoor.MOVING)
    finally:
        ctx.worker.shutdown()
        lift.close()
        body.close()
        for w in worlds.values():
            w.cabins["elevator1"].set_door(False)
            w.cabins["elevator1"].empty()


def test_the_bumper_rides_along_and_reports_in_the_odometry_frame(worlds):
    """After a ride (the odometry frame no longer the new level's map frame), a body driven
    into the corridor's wall feels one bump on its rim in the odometry frame, through the
    drifting odometry the evaluations wrap it in too."""
    from pmnav_bt.hazards import HazardKind
    from pmnav_bt.sim.odometry import NoisyOdometry

    body = LevelBody(worlds, "L3", Pose2D(6.0, 0.2, math.pi / 2), width=160, height=120)
    drifting = NoisyOdometry(body, noise=0.05, seed=3)
    try:
        body.carry("L4", Pose2D(9.0, 0.2, math.pi / 2))  # 3 m on: odometry stays at x = 6
        drifting.set_velocity(0.3, 0.0)
        for _ in range(200):
            body.clock.wait(0.05)
            if drifting.motion_status() == MotionStatus.BLOCKED:
                break
        (bump,) = body.hazards()
        assert bump.kind == HazardKind.BUMP
        o = body.pose()
        assert o.x == pytest.approx(6.0, abs=0.05)
        assert math.dist(bump.point, (o.x, o.y)) == pytest.approx(body.body.radius)
        assert body.blocked_by() == bump
        (felt,) = drifting.hazards()
        d = drifting.pose()
        assert math.dist(felt.point, (d.x, d.y)) == pytest.approx(body.body.radius)
    finally:
        body.close()
