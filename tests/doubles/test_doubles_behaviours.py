"""Behaviours on the seams' test doubles (no pybullet): failure codes from jobs, the
coarse choice in the worker, typed plan starts and constraints, refinement ranges."""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.capture import CaptureViews
from pmnav_bt.behaviours.localize import localization_yaws, read_signs
from pmnav_bt.behaviours.motion import (
    OPENING_LOOK_AGAIN_S,
    OPENING_LOOKS,
    CheckOpening,
    MoveToward,
)
from pmnav_bt.behaviours.planning import MakePlan
from pmnav_bt.behaviours.search import CoarseDirection, FineDirection, target_entity
from pmnav_bt.errors import SensorError, VlmError
from pmnav_bt.failures import Failure, FailureCode
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.seams import CoarseChoice, Entity, PlanConstraints, Pose2D
from pmnav_bt.testing.doubles import (
    FakeCoarseDirection,
    FakePlanner,
    FakeRefiner,
    ScriptedGrounder,
)

EAST = Pose2D(4.0, 0.0, 0.0)  # straight_office: the corridor runs east along y = 0


@pytest.fixture(scope="module")
def building():
    return load_building("straight_office")


def search_views(rig, landmark: str):
    """A plan step for ``landmark`` as the target, and the search views taken for it."""
    step = rig.ctx.planner.plan(rig.pm, "start", landmark).steps[-1]  # {landmark: arrive}
    assert step.look_for == landmark
    rig.set(target=step)
    cap = CaptureViews("SearchViews", rig.ctx, lambda b: [0.0, math.radians(30)], target_entity)
    assert rig.run(cap)[-1] == Status.SUCCESS
    return rig.get("views")


def test_a_silent_camera_fails_sensor_timeout_not_an_escape(make_rig, pm):
    r = make_rig(EAST)
    r.base.observe_error = SensorError("no camera frame on /camera/image_raw for 1.0 s")
    seen = r.run(CaptureViews("Views", r.ctx, localization_yaws, read_signs))
    assert seen[-1] == Status.FAILURE
    assert r.failure.code == FailureCode.SENSOR_TIMEOUT
    assert "no camera frame on /camera/image_raw" in r.failure.message


def test_a_buggy_grounder_fails_internal_error_with_its_message(make_rig, pm):
    r = make_rig(EAST, grounder=ScriptedGrounder(pm))
    r.ctx.grounder.error = ZeroDivisionError("division by zero")
    seen = r.run(CaptureViews("Views", r.ctx, localization_yaws, read_signs))
    assert seen[-1] == Status.FAILURE
    assert r.failure.code == FailureCode.INTERNAL_ERROR
    assert "ZeroDivisionError: division by zero" in r.failure.message


def test_the_coarse_choice_runs_in_the_worker(make_rig, pm):
    r = make_rig(EAST)
    views = search_views(r, "room2")
    coarse = CoarseDirection("CoarseDirection", r.ctx)
    coarse.tick_once()
    assert coarse.status == Status.RUNNING and r.ctx.coarse.threads == []  # not in the tick
    seen = r.run(coarse)
    assert seen[-1] == Status.SUCCESS
    assert len(r.ctx.coarse.threads) == 1 and r.ctx.coarse.threads[0].startswith("pmnav-worker")
    choice = r.get("choice")
    assert isinstance(choice, CoarseChoice) and choice.view in views
    assert choice.detection.entity == Entity.room("room2")


def test_a_vlm_error_in_the_coarse_direction_fails_vlm_error(make_rig, pm):
    r = make_rig(EAST, coarse=FakeCoarseDirection(error=VlmError("timed out")))
    search_views(r, "room2")
    assert r.run(CoarseDirection("CoarseDirection", r.ctx))[-1] == Status.FAILURE
    assert r.failure == Failure(FailureCode.VLM_ERROR, "choosing the coarse direction: timed out")


def test_a_target_in_no_view_fails_target_not_found(make_rig, pm):
    r = make_rig(EAST, grounder=ScriptedGrounder(pm, hidden=frozenset({"room2"})))
    search_views(r, "room2")
    assert r.run(CoarseDirection("CoarseDirection", r.ctx))[-1] == Status.FAILURE
    assert r.failure.code == FailureCode.TARGET_NOT_FOUND


def test_fine_direction_takes_the_range_from_the_refinement_else_from_the_map(make_rig, pm):
    for gives_range in (True, False):
        r = make_rig(Pose2D(4.0, 0.3, 0.0), refiner=FakeRefiner(gives_range))
        search_views(r, "room2")
        r.run(CoarseDirection("CoarseDirection", r.ctx))
        assert r.run(FineDirection("FineDirection", r.ctx))[-1] == Status.SUCCESS
        s = r.get("sighting")
        assert s.entity == Entity.room("room2") and s.map_xy == (10.0, 1.1)
        assert math.dist(s.odom_xy, s.map_xy) < 1e-6  # exact odometry: seen where it is


def test_make_plan_gives_the_planner_the_pose_and_the_constraints(make_rig, pm):
    r = make_rig(Pose2D(10.0, 0.2, math.pi))
    first = r.ctx.planner.inner.plan(r.pm, Pose2D(11.0, 0.2, math.pi), "Kitchen").steps[0]
    r.set(
        goal="Kitchen",
        map_T_odom=(1.0, 0.0, 0.0),
        avoid_landmarks=frozenset({first.look_for}),
        blocked_segments=frozenset(),
    )
    assert r.run(MakePlan("Plan", r.ctx))[-1] == Status.SUCCESS
    (start,) = r.ctx.planner.starts
    assert start == Pose2D(11.0, 0.2, math.pi)  # map_T_odom applied; radians, not text
    avoided = PlanConstraints(avoid_landmarks=frozenset({first.look_for}))
    assert r.ctx.planner.constraints == [avoided]
    assert all(s.look_for != first.look_for for s in r.get("plan").steps)


def test_a_buggy_planner_fails_internal_error(make_rig, pm):
    r = make_rig(EAST, planner=FakePlanner(error=KeyError("seg99")))
    r.set(goal="Kitchen")
    assert r.run(MakePlan("Plan", r.ctx))[-1] == Status.FAILURE
    assert r.failure.code == FailureCode.INTERNAL_ERROR
    assert r.failure.message == "planning: KeyError: 'seg99'"


def test_a_failure_during_a_recovery_keeps_the_root_cause(make_rig, pm):
    r = make_rig(EAST)
    root = Failure(FailureCode.TARGET_NOT_FOUND, "room2 not seen in 6 views")
    r.set(recovering_from=root)
    r.base.observe_error = SensorError("no camera frame")
    r.run(CaptureViews("RelocalizeViews", r.ctx, localization_yaws, read_signs))
    assert r.failure.code == FailureCode.SENSOR_TIMEOUT and r.failure.cause == root
    assert str(r.failure).endswith(f"(after {root})")


def test_the_way_watch_reports_a_silent_camera_not_an_obstacle(make_rig, pm):
    r = make_rig(EAST)
    plan = r.ctx.planner.plan(r.pm, "start", "room13")
    r.set(target=plan.steps[-1])
    r.base.observe_error = SensorError("no camera frame")
    seen = r.run(MoveToward("MoveOn", r.ctx, keep=1.0))
    assert seen[-1] == Status.FAILURE
    assert r.failure.code == FailureCode.SENSOR_TIMEOUT  # was reported as BLOCKED
    assert r.base.velocity_command == (0.0, 0.0)


def test_check_opening_fails_when_a_wall_fills_the_way(make_rig, pm):
    for open_ahead, status, looks in ((True, Status.SUCCESS, 1), (False, Status.FAILURE, 3)):
        r = make_rig(EAST, grounder=ScriptedGrounder(pm, open_ahead=open_ahead))
        plan = r.ctx.planner.plan(r.pm, "start", "room13")
        r.set(plan=plan, target=plan.steps[0])
        assert r.run(CheckOpening("ForkChoice", r.ctx))[-1] == status
        assert r.ctx.grounder.calls == ["surfaces"] * looks
    assert f"in {OPENING_LOOKS} looks" in r.failure.message


@dataclass
class CrossedOnce(ScriptedGrounder):
    """The way ahead hidden in the first look (someone crossing the junction), open after."""

    def surfaces(self, obs):
        self.open_ahead = bool(self.calls)
        return super().surfaces(obs)


def test_check_opening_looks_again_when_the_way_was_hidden(make_rig, pm):
    """Someone crossing in front of the robot at a fork hides the way for a look: the
    check looks again a few seconds later instead of giving the fork up."""
    r = make_rig(EAST, grounder=CrossedOnce(pm))
    plan = r.ctx.planner.plan(r.pm, "start", "room13")
    r.set(plan=plan, target=plan.steps[0])
    t0 = r.ctx.now()
    leaf = CheckOpening("ForkChoice", r.ctx)
    assert r.run(leaf)[-1] == Status.SUCCESS
    assert r.ctx.grounder.calls == ["surfaces", "surfaces"]
    assert r.ctx.now() - t0 >= OPENING_LOOK_AGAIN_S


@pytest.mark.parametrize("share", [0.2, 0.8])
def test_whether_a_sign_is_in_reach_is_weighed_in_the_worker(make_rig, share):
    """The belief's share with a sign in reach takes tens of ms on a large belief: the leaf
    asks the worker and says RUNNING until the answer comes (then SUCCESS under half)."""
    import threading

    from pmnav_bt.behaviours.belief import NO_SIGN_SHARE, NoSignInReach

    asked: list[str] = []

    class Belief:
        ref = EAST

        def sign_in_reach(self, pose):
            asked.append(threading.current_thread().name)
            return share

    r = make_rig(EAST)
    r.set(belief=Belief())
    leaf = NoSignInReach("NoSignInReach", r.ctx)
    r.expect(r.run(leaf), Status.SUCCESS if share < NO_SIGN_SHARE else Status.FAILURE)
    assert len(asked) == 1 and asked[0].startswith("pmnav-worker")
    assert leaf.feedback_message == f"{share:.0%} of the belief puts a sign in reach"
