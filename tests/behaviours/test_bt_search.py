"""Search: coarse direction, grounding, fine direction, verification.

Tests marked ``world`` take their views with a real CaptureViews and the ground-truth
grounder in pybullet; the others run on the test doubles. The targets are steps of a real
plan: from (0, 29) south to room3, {room4: go straight}
(door (1.2, 22)), {room5: go straight} (door (1.2, 14)), {room3: arrive}.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.capture import CaptureViews, search_yaws
from pmnav_bt.behaviours.search import (
    CORRECTION_GAIN,
    VERIFY_TOLERANCE,
    CoarseDirection,
    FineDirection,
    Ground,
    Verify,
    target_bearing,
    target_entity,
)
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import se2_apply
from pmnav_bt.perception.coarse import DetectorCoarseDirection
from pmnav_bt.planning.resolve import sign_text
from pmnav_bt.pose.landmark_fix import Sighting
from pmnav_bt.seams import CoarseChoice, Entity, Pose2D
from pmnav_bt.testing.doubles import ScriptedGrounder
from pmnav_bt.trees.pmnav import step_subtree

# On the start-turn1 corridor facing south, 4.5 m short of room4's door.
NORTH_OF_ROOM4 = Pose2D(0.0, 26.5, math.radians(-90))
ROOM4_DOOR = (1.2, 22.0)
NEARER_ROOM4 = Pose2D(0.0, 25.0, math.radians(-90))  # 3 m short: read at 160 px


def targets(rig) -> dict:
    plan = rig.plan("0,29,-90", "room3")
    steps = {s.landmark: s for s in plan.steps}
    assert list(steps) == ["room4", "room5", "room3"]
    return steps


def search(rig, target) -> list:
    """Put ``target`` on the blackboard and take the search views for it."""
    rig.set(target=target)
    cap = CaptureViews("SearchViews", rig.ctx, lambda b: search_yaws(None), target_entity)
    rig.expect(rig.run(cap, max_ticks=300), Status.SUCCESS)
    return rig.get("views")


def choice(rig) -> tuple:
    """The chosen view and detection on the blackboard."""
    c: CoarseChoice = rig.get("choice")
    return c.view, c.detection


def rel_deg(view) -> int:
    return round(math.degrees(view.relative_yaw) / 10) * 10


def test_the_target_is_a_typed_entity_whose_sign_a_person_reads(make_rig):
    rig = make_rig(NORTH_OF_ROOM4)
    steps = targets(rig)
    cap = CaptureViews("SearchViews", rig.ctx, lambda b: [], target_entity)
    for landmark, text in [("room4", "104 Laboratory"), ("room5", "105")]:
        rig.set(target=steps[landmark])
        assert target_entity(cap) == Entity.room(landmark)
        assert sign_text(rig.pm.building, target_entity(cap)) == text
    turn = rig.plan("0,3,-90", "room11").steps[0]  # {turn1: turn left}: nothing to read
    rig.set(target=turn)
    assert target_entity(cap) is None


@pytest.mark.world
def test_coarse_direction_picks_the_view_with_the_best_score(make_rig):
    rig = make_rig(NORTH_OF_ROOM4, width=320, height=240)  # room4 readable in two views
    views = search(rig, targets(rig)["room4"])
    seen = [(v, d) for v in views for d in v.detections]
    assert len({id(v) for v, _ in seen}) >= 2  # a real choice between views
    coarse = CoarseDirection("CoarseDirection", rig.ctx)
    rig.expect(rig.run(coarse), Status.SUCCESS)
    view, det = choice(rig)
    best_view, best_det = max(seen, key=lambda vd: vd[1].score)
    assert view is best_view and det is best_det
    assert det.label == "104 Laboratory" and det.mask is not None
    assert rel_deg(view) in (0, 30)  # the door is ahead on the left
    assert f"{math.degrees(view.relative_yaw):+.0f} deg" in coarse.feedback_message


@pytest.mark.world
def test_coarse_direction_fails_target_not_found_when_no_view_shows_it(make_rig):
    rig = make_rig(NORTH_OF_ROOM4)
    views = search(rig, targets(rig)["room3"])  # 16 m away: the sign is unreadable
    assert all(v.detections == () for v in views)
    coarse = CoarseDirection("CoarseDirection", rig.ctx)
    rig.expect(rig.run(coarse), Status.FAILURE)
    assert rig.failure.code == FailureCode.TARGET_NOT_FOUND
    assert rig.failure.message == f"room3 not seen in {len(views)} views"
    assert rig.get("choice") is None


@pytest.mark.world
def test_coarse_direction_ignores_detections_below_min_score(make_rig):
    rig = make_rig(NORTH_OF_ROOM4)
    views = search(rig, targets(rig)["room4"])
    scores = [d.score for v in views for d in v.detections]
    assert scores and max(scores) < 0.9
    rig.ctx.coarse = DetectorCoarseDirection(rig.ctx.grounder, min_score=0.9)
    rig.expect(rig.run(CoarseDirection("Strict", rig.ctx)), Status.FAILURE)
    assert rig.failure.code == FailureCode.TARGET_NOT_FOUND
    rig.ctx.coarse = DetectorCoarseDirection(rig.ctx.grounder, min_score=0.3)
    rig.expect(rig.run(CoarseDirection("Lenient", rig.ctx)), Status.SUCCESS)


def test_ground_faces_the_coarse_direction_and_grounds_in_a_fresh_frame(make_rig, pm):
    rig = make_rig(NORTH_OF_ROOM4, grounder=ScriptedGrounder(pm, masks=True))
    search(rig, targets(rig)["room4"])
    rig.run(CoarseDirection("CoarseDirection", rig.ctx))
    view, det = choice(rig)
    obs = view.observation
    toward = obs.pose.yaw + obs.intrinsics.pixel_bearing(det.centre[0])
    assert rig.yaw_error(rig.true_pose().yaw, toward) > 0.2  # the sweep ended elsewhere

    ground = Ground("Grounding", rig.ctx)
    seen = rig.run(ground, max_ticks=100)
    rig.expect(seen, Status.SUCCESS)
    assert len(seen) > 3  # turned first, then took a frame in the worker
    assert rig.yaw_error(rig.true_pose().yaw, toward) <= 0.035
    assert rig.stopped()
    view2, det2 = choice(rig)
    assert view2 is not view  # a fresh frame ...
    assert rig.yaw_error(view2.observation.pose.yaw, toward) <= 0.035  # ... facing the target
    assert det2.label == det.label and det2.mask is not None and det2 in view2.detections
    k = view2.observation.intrinsics
    assert abs(det2.centre[0] - k.cx) < abs(det.centre[0] - obs.intrinsics.cx)  # more central


def test_ground_keeps_the_coarse_detection_when_the_fresh_frame_misses(make_rig, pm):
    rig = make_rig(NORTH_OF_ROOM4, grounder=ScriptedGrounder(pm, masks=True))
    search(rig, targets(rig)["room4"])
    rig.run(CoarseDirection("CoarseDirection", rig.ctx))
    coarse = rig.get("choice")
    rig.ctx.grounder.hidden = frozenset({"room4"})  # the fresh frame cannot read it
    rig.expect(rig.run(Ground("Grounding", rig.ctx), max_ticks=100), Status.SUCCESS)
    assert rig.get("choice") is coarse
    assert rig.failure is None


def test_ground_terminate_while_turning_stops_the_base(make_rig):
    rig = make_rig(NORTH_OF_ROOM4)
    search(rig, targets(rig)["room4"])
    rig.run(CoarseDirection("CoarseDirection", rig.ctx))
    ground = Ground("Grounding", rig.ctx)
    assert rig.tick(ground) == Status.RUNNING
    assert rig.body.velocity_command != (0.0, 0.0)
    ground.stop(Status.INVALID)
    assert rig.stopped()


def test_the_tree_searches_first_where_the_map_puts_the_target(make_rig):
    """The tree's search views start at the one nearest the target's bearing by the map and
    stop once it is seen: room4's door, 3 m ahead and 1.2 m to the left (22 deg), is read in
    the first view, at +30 deg, one turn (the paper's sweep turns to -90 first and reaches
    +30 at the fifth view)."""
    rig = make_rig(NEARER_ROOM4)
    rig.set(target=targets(rig)["room4"], map_T_odom=(0.0, 0.0, 0.0))
    cap = next(n for n in step_subtree(rig.ctx).iterate() if n.name == "SearchViews")
    rig.expect(rig.run(cap, max_ticks=300), Status.SUCCESS)
    views = rig.get("views")
    assert [rel_deg(v) for v in views] == [30]
    assert any(d.label == "104 Laboratory" for d in views[0].detections)
    turned = rig.true_pose().yaw - NEARER_ROOM4.yaw
    assert rig.yaw_error(turned, math.radians(30)) < math.radians(2)


def test_the_target_bearing_points_at_its_door_not_its_node(make_rig):
    """Just past room4's node, facing on south: the door (where the sign is) is on the left,
    a little behind, while the node on the centre line lies straight behind."""
    rig = make_rig(Pose2D(0.0, 21.7, math.radians(-90)))
    step = targets(rig)["room4"]
    assert step.position[1] == pytest.approx(22.0) and step.target == ROOM4_DOOR
    rig.set(target=step, map_T_odom=(0.0, 0.0, 0.0))
    cap = CaptureViews("SearchViews", rig.ctx, lambda b: [], target_entity)
    want = math.atan2(0.3, 1.2) + math.radians(90)  # the door, from the heading
    assert target_bearing(cap) == pytest.approx(want, abs=0.02)


def fine_and_verify(rig, map_T_odom):
    """CoarseDirection -> Ground -> FineDirection -> Verify on the current views, as the
    tree ticks them; the Verify behaviour, ticked once."""
    rig.set(map_T_odom=map_T_odom)
    rig.expect(rig.run(CoarseDirection("CoarseDirection", rig.ctx)), Status.SUCCESS)
    rig.expect(rig.run(Ground("Grounding", rig.ctx), max_ticks=100), Status.SUCCESS)
    rig.expect(rig.run(FineDirection("FineDirection", rig.ctx)), Status.SUCCESS)
    verify = Verify("Verification", rig.ctx)
    rig.tick(verify)
    return verify


def test_a_true_sighting_verifies_and_pulls_an_offset_map_t_odom_towards_the_truth(
    make_rig, pm, thumbnails_off_the_tick
):
    rig = make_rig(NORTH_OF_ROOM4, grounder=ScriptedGrounder(pm, masks=True))
    search(rig, targets(rig)["room4"])
    # Odometry is the map frame here; the estimate is off by (0.5, 1.0) m.
    offset = (0.5, 1.0, 0.0)
    verify = fine_and_verify(rig, offset)
    assert verify.status == Status.SUCCESS
    assert verify.feedback_message.startswith("room room4 verified")

    view, det = choice(rig)
    bearing, s = rig.get("bearing"), rig.get("sighting")
    assert bearing == pytest.approx(view.observation.intrinsics.pixel_bearing(det.centre[0]))
    assert s.entity == Entity.room("room4") and s.map_xy == ROOM4_DOOR
    assert math.dist(s.odom_xy, ROOM4_DOOR) < 0.5  # seen where the door is (odom = truth)
    p = view.observation.pose
    seen_dir = math.atan2(s.odom_xy[1] - p.y, s.odom_xy[0] - p.x)
    assert rig.yaw_error(seen_dir, p.yaw + bearing) < 0.01  # along the refined bearing
    event = rig.ctx.trace[-1]
    assert event.kind == "detection" and event.label == "room4"
    rig.wait()  # the worker's jobs after the tick
    assert event.frame is None and event.thumbnail is not None  # shrunk in the worker

    tf = rig.get("map_T_odom")
    assert tf[2] == 0.0  # one landmark: position only
    before = math.hypot(offset[0], offset[1])
    after = math.hypot(tf[0], tf[1])  # the true map_T_odom is the identity
    assert after < 0.5 and after < before / 2
    seen = se2_apply(offset, s.odom_xy)
    want = np.asarray(offset[:2]) + CORRECTION_GAIN * (np.asarray(ROOM4_DOOR) - seen)
    assert tf[:2] == pytest.approx(tuple(want))
    assert rig.get("recent_sightings") == [s]
    assert rig.failure is None


def test_verify_refits_heading_on_recent_sightings_spread_apart(make_rig, pm):
    rig = make_rig(NORTH_OF_ROOM4, grounder=ScriptedGrounder(pm, masks=True))
    search(rig, targets(rig)["room4"])
    # Earlier verified sightings of room1 and room2, seen where they are (odom = map).
    recent = [
        Sighting(Entity.room("room1"), (-1.2, 26.0), (-1.2, 26.0)),
        Sighting(Entity.room("room2"), (-1.2, 18.0), (-1.2, 18.0)),
    ]
    rig.set(recent_sightings=recent)
    wrong_heading = (0.0, 0.0, math.radians(4))
    verify = fine_and_verify(rig, wrong_heading)
    assert verify.status == Status.SUCCESS
    assert "re-fit on 3 landmarks" in verify.feedback_message
    tf = rig.get("map_T_odom")
    assert abs(tf[2]) < math.radians(1.5)  # heading re-fitted from the landmarks
    assert [r.entity for r in rig.get("recent_sightings")] == [
        Entity.room("room1"),
        Entity.room("room2"),
        Entity.room("room4"),
    ]


@pytest.mark.world
def test_a_sighting_of_the_wrong_place_fails_target_not_found(make_rig):
    # room5's door (1.2, 14) is 12 m on: unreadable. The grounder misreads another sign in
    # view as "105" (every time), so the coarse direction picks a wrong place.
    rig = make_rig(NORTH_OF_ROOM4, overrides=("grounder.false_positive_rate=1.0",))
    search(rig, targets(rig)["room5"])
    assert fine_and_verify(rig, None).status == Status.FAILURE
    s = rig.get("sighting")
    assert s.entity == Entity.room("room5") and s.map_xy == (1.2, 14.0)
    assert math.dist(s.odom_xy, s.map_xy) > VERIFY_TOLERANCE
    assert rig.failure.code == FailureCode.TARGET_NOT_FOUND
    assert "not it" in rig.failure.message
    assert rig.get("map_T_odom") is None  # no correction from a wrong sighting
    assert rig.get("recent_sightings") is None


def test_coarse_only_places_the_target_straight_ahead_at_the_map_distance(make_rig):
    rig = make_rig(NORTH_OF_ROOM4, overrides=("tree.variant=coarse_only",))
    search(rig, targets(rig)["room4"])
    rig.run(CoarseDirection("CoarseDirection", rig.ctx))
    rig.expect(rig.run(Ground("Grounding", rig.ctx), max_ticks=100), Status.SUCCESS)
    assert rig.tick(FineDirection("FineDirection", rig.ctx, refine=False)) == Status.SUCCESS
    view, _ = choice(rig)
    s, p = rig.get("sighting"), view.observation.pose
    assert rig.get("bearing") == 0.0
    assert math.dist(s.odom_xy, (p.x, p.y)) == pytest.approx(math.dist(ROOM4_DOOR, (p.x, p.y)))
    seen_dir = math.atan2(s.odom_xy[1] - p.y, s.odom_xy[0] - p.x)
    assert rig.yaw_error(seen_dir, p.yaw) < 1e-6


@pytest.mark.world
def test_detector_coarse_direction_seam_grounds_plain_views(make_rig):
    from pmnav_bt.seams import View

    rig = make_rig(NORTH_OF_ROOM4, width=320, height=240)
    captured = search(rig, targets(rig)["room4"])
    plain = [View(v.relative_yaw, v.observation) for v in captured]  # no detections
    picked = rig.ctx.coarse.choose(plain, Entity.room("room4"))
    best = max(((v, d) for v in captured for d in v.detections), key=lambda vd: vd[1].score)
    assert picked.view.relative_yaw == pytest.approx(best[0].relative_yaw)
    assert picked.detection.entity == Entity.room("room4")
    assert rig.ctx.coarse.choose(plain, Entity.room("room3")) is None  # 16 m: unreadable


def test_a_landmark_sighting_corrects_only_across_its_wall_and_joins_no_re_fit(make_rig):
    # A landmark is read by its sign, which may hang beside it (an elevator's ~1.5 m along
    # the wall): seen 1.5 m along the N-S corridor from the map's point and 0.4 m across.
    from pmnav_bt.pose.visibility import entity_xy

    rig = make_rig(NORTH_OF_ROOM4)
    desk = Entity.landmark("reception")
    map_xy = entity_xy(rig.pm, desk)
    odom_xy = (map_xy[0] - 0.4, map_xy[1] + 1.5)
    recent = [Sighting(Entity.room("room1"), (-1.2, 26.0), (-1.2, 26.0))]
    rig.set(sighting=Sighting(desk, map_xy, odom_xy), recent_sightings=recent)
    rig.set(map_T_odom=(0.0, 0.0, 0.0))
    verify = Verify("Verification", rig.ctx)
    rig.tick(verify)
    assert verify.status == Status.SUCCESS
    assert "across its wall" in verify.feedback_message
    tf = rig.get("map_T_odom")
    assert tf == pytest.approx((CORRECTION_GAIN * 0.4, 0.0, 0.0), abs=1e-9)  # not along it
    assert rig.get("recent_sightings") == recent  # no heading re-fit on its sign
