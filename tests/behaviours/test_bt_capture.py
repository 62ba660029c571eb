"""CaptureViews: the sweep, the views, early stop, cancellation. The order of the views and
the interrupts on the test doubles; what a view reads, and the panorama, in pybullet."""

from __future__ import annotations

import math

import numpy as np
import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.capture import (
    LOCALIZATION_YAWS_DEG,
    SEARCH_YAWS_DEG,
    CaptureViews,
    nearest_first,
    search_centre,
    search_yaws,
    sweep_order,
)
from pmnav_bt.behaviours.localize import (
    distinct_landmarks,
    enough_doors,
    localization_yaws,
    read_signs,
)
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import Action, wrap_angle
from pmnav_bt.seams import Entity, EntityKind, Pose2D

# On the start-turn1 corridor (x = 0) facing south: room4 (104) and room2 (102) are
# either side at y = 22 and 18, the reception desk behind.
SOUTH_AT_20 = Pose2D(0.0, 20.0, math.radians(-90))
TOL = 0.035  # rotate_command stops within 0.03 rad


def no_query(_b):
    return None


def rel_deg(views) -> list[int]:
    """The views' relative yaws in degrees, to the nearest 10 (turns stop within 1.7 deg)."""
    return [round(math.degrees(v.relative_yaw) / 10) * 10 for v in views]


@pytest.mark.parametrize(
    "last, missing",
    [(None, None), (Action.GO_STRAIGHT, None), (Action.TURN_LEFT, -90), (Action.TURN_RIGHT, 90)],
)
def test_search_yaws_leave_out_the_view_the_last_turn_rules_out(last, missing):
    got = [round(math.degrees(y)) for y in search_yaws(last)]
    assert got == [y for y in SEARCH_YAWS_DEG if y != missing]
    assert len(got) == (7 if missing is None else 6)


def test_search_views_centre_on_a_target_off_to_a_side():
    """Ahead (within 45 deg): the paper's views. Level with a door or past it, where its
    sign (beside it) is out of the forward fan: the views centre on it, on the 30 deg grid."""
    r = math.radians
    assert search_centre(r(40)) == 0.0 and search_centre(r(-45)) == 0.0
    assert search_centre(r(100)) == pytest.approx(r(90))
    assert search_centre(r(-170)) == pytest.approx(r(-180))
    got = [round(math.degrees(y)) for y in search_yaws(Action.TURN_LEFT, search_centre(r(80)))]
    assert got == [90, 120, 60, 150, 30, 180]  # 90 + the paper's views, -90 left out


def test_sweep_order_starts_at_the_nearer_extreme():
    r = math.radians
    assert sweep_order([]) == []
    assert sweep_order([r(0), r(30), r(-60)]) == [r(30), r(0), r(-60)]  # -60 is farther
    assert sweep_order([r(0), r(-30), r(60)]) == [r(-30), r(0), r(60)]
    left = sweep_order(search_yaws(Action.TURN_LEFT))  # -90 left out: start at -60
    assert [round(math.degrees(y)) for y in left] == [-60, -30, 0, 30, 60, 90]


def test_search_views_are_taken_nearest_the_targets_bearing_first():
    """The view nearest the bearing, then outwards on the side it leans to, then the other
    side; a bearing on a view: the side with fewer views first (fewer turns back)."""
    r = math.radians

    def order(yaws, bearing_deg):
        return [round(math.degrees(y)) for y in nearest_first(yaws, r(bearing_deg))]

    paper = search_yaws(None)
    assert order(paper, 0) == [0, 30, 60, 90, -30, -60, -90]
    assert order(paper, 20) == [30, 0, -30, -60, -90, 60, 90]  # 20 leans back towards 0
    assert order(paper, -50) == [-60, -30, 0, 30, 60, 90, -90]
    assert order(search_yaws(Action.TURN_LEFT), 0) == [0, -30, -60, 30, 60, 90]
    assert order([], 0) == []
    # Centred on a target behind the robot: views past +-180 deg, nearest by the angle.
    behind = search_yaws(None, search_centre(r(-170)))
    assert order(behind, 175) == [-180, -210, -240, -270, -150, -120, -90]


def test_capture_turns_through_the_yaws_taking_one_view_at_each(make_rig):
    rig = make_rig(SOUTH_AT_20)
    cap = CaptureViews("Views", rig.ctx, localization_yaws, read_signs)
    turns, last = [], [SOUTH_AT_20.yaw]

    def turned() -> bool:  # the turn of each tick, signed
        yaw = rig.true_pose().yaw
        turns.append(wrap_angle(yaw - last[0]))
        last[0] = yaw
        return False

    seen = rig.run(cap, max_ticks=300, until=turned)

    rig.expect(seen, Status.SUCCESS)
    assert len(seen) > 6  # it turned between views: no panorama in one tick
    views = rig.get("views")
    want = [wrap_angle(y) for y in sweep_order(localization_yaws(cap))]
    assert rel_deg(views) == [30, 90, 150, -150, -90, -30]
    for v, rel in zip(views, want, strict=True):
        assert rig.yaw_error(v.relative_yaw, rel) <= TOL
        # each frame was taken facing its yaw (the observation's pose is the body's)
        assert rig.yaw_error(v.observation.pose.yaw, SOUTH_AT_20.yaw + rel) <= TOL
        assert v.observation.rgb.shape == (120, 160, 3)
    # One sweep to the left, 30 -> 330 deg, no back and forth; it ends facing the last view.
    assert all(t >= 0.0 for t in turns)
    assert sum(turns) == pytest.approx(math.radians(330), abs=0.1)
    assert rig.yaw_error(rig.true_pose().yaw, SOUTH_AT_20.yaw + want[-1]) <= TOL
    assert rig.stopped()
    assert rig.true_pose().x == pytest.approx(0.0) and rig.true_pose().y == pytest.approx(20.0)
    # The signs either side were read in the views that face them.
    labels = dict(zip(rel_deg(views), (v.detections for v in views), strict=True))
    assert "104 Laboratory" in {d.label for d in labels[150]}  # door at (1.2, 22), behind left
    assert "102 Pharmacy" in {d.label for d in labels[-30]}  # door at (-1.2, 18), ahead right
    assert rig.failure is None


def test_capture_keeps_the_given_order_without_sweep(make_rig):
    rig = make_rig(SOUTH_AT_20)
    yaws = [math.radians(60), math.radians(-30)]
    cap = CaptureViews("Views", rig.ctx, lambda b: yaws, no_query, sweep=False)
    rig.expect(rig.run(cap, max_ticks=200), Status.SUCCESS)
    views = rig.get("views")
    assert rel_deg(views) == [60, -30]
    assert all(v.detections is None for v in views)  # nothing to ground: frames only


def test_search_views_after_a_left_turn_skip_minus_90(make_rig):
    rig = make_rig(SOUTH_AT_20)
    rig.set(last_action=Action.TURN_LEFT)
    cap = CaptureViews(
        "SearchViews", rig.ctx, lambda b: search_yaws(b.get("last_action")), no_query
    )
    rig.expect(rig.run(cap, max_ticks=300), Status.SUCCESS)
    rels = rel_deg(rig.get("views"))
    assert rels == [-60, -30, 0, 30, 60, 90]


def test_capture_stops_early_once_enough(make_rig):
    rig = make_rig(SOUTH_AT_20)
    cap = CaptureViews(
        "Views", rig.ctx, localization_yaws, read_signs, enough=lambda views: len(views) >= 2
    )
    rig.expect(rig.run(cap, max_ticks=200), Status.SUCCESS)
    views = rig.get("views")
    assert rel_deg(views) == [30, 90]
    assert rig.yaw_error(rig.true_pose().yaw, SOUTH_AT_20.yaw + math.radians(90)) <= TOL


@pytest.mark.world
def test_localization_capture_stops_once_enough_doors_are_read(make_rig):
    # At (0, 24) facing south, room4 (104) is read at +30 deg and room1 (101) at -150 deg,
    # the fourth view: two doors, so the last two views are not needed.
    rig = make_rig(Pose2D(0.0, 24.0, math.radians(-90)))
    ctx = rig.ctx
    cap = CaptureViews(
        "Views",
        ctx,
        localization_yaws,
        read_signs,
        enough=lambda views: enough_doors(views, n=2),
    )
    rig.expect(rig.run(cap, max_ticks=300), Status.SUCCESS)
    views = rig.get("views")
    assert len(views) < len(LOCALIZATION_YAWS_DEG)
    assert enough_doors(views, n=2)
    assert not enough_doors(views[:-1], n=2)  # it stopped at the first view that did it
    doors = {e for e in distinct_landmarks(views) if e.kind is EntityKind.ROOM}
    assert doors == {Entity.room("room1"), Entity.room("room4")}


def test_terminate_while_turning_stops_the_base(make_rig):
    rig = make_rig(SOUTH_AT_20)
    cap = CaptureViews("Views", rig.ctx, localization_yaws, read_signs)
    assert rig.tick(cap) == Status.RUNNING
    assert rig.body.velocity_command[1] > 0.0  # turning left towards +30 deg
    rig.wait()
    assert rig.tick(cap) == Status.RUNNING
    cap.stop(Status.INVALID)  # what a higher-priority branch or an interrupt does
    assert cap.status == Status.INVALID
    assert rig.stopped()
    turned = rig.true_pose().yaw
    assert 0.0 < turned - SOUTH_AT_20.yaw < math.radians(30)  # on its way to +30 deg
    rig.wait(1.0)
    assert rig.true_pose().yaw == turned  # it did not go on turning
    assert rig.get("views") is None


def test_terminate_with_a_frame_in_flight_cancels_the_job_and_stops(make_rig):
    rig = make_rig(SOUTH_AT_20)
    release = rig.hold_worker()  # the frame job stays queued behind this one
    cap = CaptureViews("Views", rig.ctx, lambda b: [0.0], read_signs)
    assert rig.tick(cap) == Status.RUNNING  # already facing 0: the frame is requested
    job = cap._job
    assert job is not None and not job.done()
    assert rig.tick(cap) == Status.RUNNING  # still waiting: a tick never blocks
    rig.body.set_velocity(0.2, 0.0)  # (as if something else had the base moving)
    cap.stop(Status.INVALID)
    assert job.cancelled.is_set()
    release.set()
    rig.ctx.worker.drain()
    assert not job.started()  # dropped before it ran
    assert rig.stopped()
    assert rig.get("views") is None
    # Ticked again, it starts afresh and completes.
    rig.expect(rig.run(cap, max_ticks=20), Status.SUCCESS)
    assert len(rig.get("views")) == 1


@pytest.mark.world
def test_a_frame_the_grounder_cannot_read_fails_backend_error(make_rig):
    rig = make_rig(SOUTH_AT_20, segmentation=False)  # the ground-truth grounder needs it
    cap = CaptureViews("Views", rig.ctx, lambda b: [0.0, math.radians(30)], read_signs)
    seen = rig.run(cap, max_ticks=50)
    rig.expect(seen, Status.FAILURE)
    assert len(seen) == 2  # request the frame, then collect the error
    assert rig.failure.code == FailureCode.BACKEND_ERROR
    assert "segmentation" in rig.failure.message
    assert rig.get("views") is None


def _panorama(rig):
    from pmnav_bt.trees.localize import panorama_subtree

    rig.expect(rig.run(panorama_subtree(rig.ctx), max_ticks=800), Status.SUCCESS)
    return rig.get("views")


@pytest.mark.world
def test_a_panorama_reading_two_signs_takes_six_views_at_most(make_rig):
    rig = make_rig(SOUTH_AT_20)  # room2 and room4 either side
    views = _panorama(rig)
    assert len(views) <= len(LOCALIZATION_YAWS_DEG)
    assert len(distinct_landmarks(views)) >= 2


@pytest.mark.world
def test_a_panorama_reading_fewer_takes_the_six_views_between_the_first(make_rig, pm):
    """A plate on the seam of two 60-degree views is cut in both: with fewer than two
    signs read, the panorama goes on round through the directions half-way between."""
    from pmnav_bt.pose.visibility import Visibility

    vis = Visibility.of(pm, 2.0)  # a reader of short range: no sign within 2 m here
    bare = next(p for p in vis.lattice_points if not p.readable)
    start = Pose2D(*bare.xy, pm.segments[bare.segment - 1].heading)
    rig = make_rig(start, overrides=("grounder.max_range=2.0",))
    views = _panorama(rig)
    assert len(distinct_landmarks(views)) < 2
    assert len(views) == 2 * len(LOCALIZATION_YAWS_DEG)
    first = [v.observation.pose.yaw for v in views[:6]]
    between = [v.observation.pose.yaw for v in views[6:]]
    assert [round(math.degrees(wrap_angle(y - start.yaw))) % 360 for y in first] == pytest.approx(
        list(LOCALIZATION_YAWS_DEG), abs=3
    )
    for y in between:  # each half-way between two of the first six
        assert min(abs(wrap_angle(y - f)) for f in first) == pytest.approx(
            math.radians(30), abs=0.06
        )


def test_an_extending_capture_adds_its_views_to_those_on_the_blackboard(make_rig):
    rig = make_rig(SOUTH_AT_20)
    first = CaptureViews("Views", rig.ctx, lambda b: [0.0], no_query)
    rig.expect(rig.run(first, max_ticks=100), Status.SUCCESS)
    more = CaptureViews("More", rig.ctx, lambda b: [math.radians(30)], no_query, extend=True)
    rig.expect(rig.run(more, max_ticks=300), Status.SUCCESS)
    views = rig.get("views")
    assert len(views) == 2 and views[0].relative_yaw == pytest.approx(0.0, abs=TOL)
    again = CaptureViews("Again", rig.ctx, lambda b: [0.0], no_query)  # not extending
    rig.expect(rig.run(again, max_ticks=100), Status.SUCCESS)
    assert len(rig.get("views")) == 1


@pytest.mark.world
def test_in_a_bare_stretch_the_belief_skips_the_views_between(make_rig, pm):
    """Where the belief so far puts no sign in reach, the six views between are not
    worth their turn: a second panorama there stops at six views."""
    from pmnav_bt.pose.belief import CorridorBelief
    from pmnav_bt.pose.visibility import Visibility

    vis = Visibility.of(pm, 2.0)
    bare = next(p for p in vis.lattice_points if not p.readable)
    start = Pose2D(*bare.xy, pm.segments[bare.segment - 1].heading)
    rig = make_rig(start, overrides=("grounder.max_range=2.0",))
    b = CorridorBelief(pm, read_range=2.0)
    views = _panorama(rig)
    assert len(views) == 12  # no belief yet: the views between are taken
    from pmnav_bt.pose.glimpse import Glimpse

    b.observe(Glimpse(views[0].observation.pose, {}), axis_odom=start.yaw)  # odom = map
    b.logw[:] = -50.0  # a belief sure of the place: only the truth is live
    tfs = b.map_T_odoms()
    truth = np.linalg.norm(tfs[:, :2], axis=1) < 0.3  # odometry is the map here
    turn = np.abs(np.angle(np.exp(1j * tfs[:, 2])))
    b.logw[truth & (turn < 0.1)] = 0.0
    assert b.sign_in_reach(rig.base.pose()) < 1e-6
    rig.set(belief=b)
    assert len(_panorama(rig)) == len(LOCALIZATION_YAWS_DEG)
