"""FixPosition and Explore against the simulator, on views a real CaptureViews took."""

from __future__ import annotations

import math

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.capture import CaptureViews
from pmnav_bt.behaviours.localize import (
    Explore,
    FixPosition,
    enough_doors,
    localization_yaws,
    read_signs,
)
from pmnav_bt.failures import FailureCode
from pmnav_bt.seams import Pose2D

pytestmark = pytest.mark.world  # a pybullet world: these tests need geometry

SOUTH = math.radians(-90)


def capture(rig, yaws=localization_yaws, enough=None):
    """Run a localization panorama to the end; its views (also on the blackboard)."""
    cap = CaptureViews("LocalizeViews", rig.ctx, yaws, read_signs, enough=enough)
    rig.expect(rig.run(cap, max_ticks=400), Status.SUCCESS)
    return rig.get("views")


def drive(rig, v: float, w: float, seconds: float) -> None:
    """Drive the body open-loop for a while (sim time)."""
    rig.body.set_velocity(v, w)
    rig.base.clock.wait(seconds)
    rig.body.stop()


def test_fix_from_doors_in_view_maps_drifted_odometry_onto_the_true_pose(make_rig):
    rig = make_rig(Pose2D(0.0, 28.0, SOUTH), noise=0.05, seed=5)
    # Drift: a turn on the spot and 6 m down the corridor on noisy odometry.
    drive(rig, 0.0, 1.5, 2 * math.pi / 1.5)
    drive(rig, 0.3, 0.0, 20.0)
    true, odom = rig.true_pose(), rig.base.pose()
    assert math.hypot(true.x - odom.x, true.y - odom.y) > 0.8  # odometry is well off ...
    assert rig.yaw_error(true.yaw, odom.yaw) > math.radians(8)  # ... in position and heading

    ctx = rig.ctx
    capture(rig, enough=enough_doors)
    fix = FixPosition("Fix", ctx)
    seen = rig.run(fix)  # the fix is computed in the worker: RUNNING, then SUCCESS
    rig.expect(seen, Status.SUCCESS)
    assert seen[0] == Status.RUNNING
    assert rig.get("fix_attempts") == 1
    tf = rig.get("map_T_odom")
    assert tf is not None and len(tf) == 3
    est, true = rig.estimate(), rig.true_pose()
    assert math.hypot(est.x - true.x, est.y - true.y) < 0.3
    assert rig.yaw_error(est.yaw, true.yaw) < math.radians(5)
    event = ctx.trace[-1]
    assert event.kind == "fix" and event.data["attempts"] == 1
    assert event.data["map_pose"] == pytest.approx([est.x, est.y, est.yaw])
    assert "from room " in fix.feedback_message
    assert rig.failure is None


def test_fix_facing_a_blank_wall_fails_localization_failed(make_rig):
    # At turn1, facing the blank south wall of the corner (1.2 m away).
    rig = make_rig(Pose2D(0.0, 0.0, SOUTH))
    views = capture(rig, yaws=lambda b: [0.0, math.radians(10)])
    assert all(v.detections == () for v in views)
    fix = FixPosition("Fix", rig.ctx)
    rig.expect(rig.run(fix), Status.FAILURE)
    assert rig.failure.code == FailureCode.LOCALIZATION_FAILED
    assert "0 landmark(s)" in rig.failure.message and "two are needed" in rig.failure.message
    assert rig.get("map_T_odom") is None
    assert rig.get("fix_attempts") == 1
    rig.expect(rig.run(fix), Status.FAILURE)  # each try counts (SDF's d)
    assert rig.get("fix_attempts") == 2


def test_fix_without_views_fails_localization_failed(make_rig):
    rig = make_rig(Pose2D(0.0, 20.0, SOUTH))
    rig.set(fix_attempts=3)
    fix = FixPosition("Fix", rig.ctx)
    rig.expect(rig.run(fix), Status.FAILURE)
    assert rig.failure.code == FailureCode.LOCALIZATION_FAILED
    assert rig.get("fix_attempts") == 4


def test_explore_turns_to_the_most_open_view_and_drives_on(make_rig):
    rig = make_rig(Pose2D(0.0, 20.0, SOUTH))
    # Views straight down the corridor (open) and at the east wall (1.2 m); it ends facing east.
    capture(rig, yaws=lambda b: [0.0, math.radians(90)])
    assert rig.yaw_error(rig.true_pose().yaw, 0.0) < 0.05
    walk = Explore("Walk", rig.ctx, distance=1.5)
    seen = rig.run(walk, max_ticks=200)
    rig.expect(seen, Status.SUCCESS)
    p = rig.true_pose()
    assert rig.yaw_error(p.yaw, SOUTH) < 0.1
    assert p.x == pytest.approx(0.0, abs=0.1) and p.y == pytest.approx(18.5, abs=0.2)
    assert rig.stopped()


def test_explore_blocked_is_best_effort_success(make_rig):
    rig = make_rig(Pose2D(0.0, 20.0, SOUTH))
    rig.add_obstacle(0.0, 19.0, size=0.6)
    rig.set(views=[])  # no views: keep the current heading
    walk = Explore("Walk", rig.ctx, distance=2.0)
    rig.expect(rig.run(walk, max_ticks=200), Status.SUCCESS)
    assert "blocked" in walk.feedback_message
    assert rig.true_pose().y == pytest.approx(19.3 + 0.17, abs=0.05)  # against the box
    assert rig.body.stats.collisions == 1
    assert rig.stopped()


def test_a_fix_forgets_the_sightings_kept_for_heading_re_fits(make_rig):
    # Sightings verified before this fix were made in an odometry frame that the panorama's
    # spin has since turned: kept, they would re-fit the heading off by that turn.
    from pmnav_bt.localization import Sighting
    from pmnav_bt.seams import Entity

    rig = make_rig(Pose2D(0.0, 28.0, SOUTH))
    stale = [
        Sighting(Entity.room("room1"), (-1.2, 26.0), (3.0, 25.0)),
        Sighting(Entity.room("room2"), (-1.2, 18.0), (5.0, 17.5)),
    ]
    rig.set(recent_sightings=stale)
    capture(rig, enough=enough_doors)
    rig.expect(rig.run(FixPosition("Fix", rig.ctx)), Status.SUCCESS)
    assert rig.get("recent_sightings") is None
