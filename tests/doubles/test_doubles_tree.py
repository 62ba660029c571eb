"""The whole PM-Nav tree on the seams' test doubles (no pybullet): a mission, retries
and a replan, and the failure codes a run reports (with its root cause)."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.errors import SensorError
from pmnav_bt.failures import FailureCode
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.seams import Pose2D
from pmnav_bt.testing.doubles import FakePlanner, ScriptedGrounder

START = Pose2D(4.0, 0.0, 0.0)  # straight_office, facing east down the corridor
KITCHEN_DOOR = (48.5, 1.1)
MAX_TICKS = 20_000


@pytest.fixture(scope="module")
def building():
    return load_building("straight_office")


def test_a_mission_on_doubles_reaches_the_goal_door(make_rig):
    rig = make_rig(START)
    out = rig.mission("Kitchen", max_ticks=MAX_TICKS)
    assert out.success and out.failure is None, out.failure
    p = rig.true_pose()
    assert math.dist((p.x, p.y), KITCHEN_DOOR) < 1.0
    assert out.fix_attempts == 1 and out.replans == 0
    kinds = [e.kind for e in rig.ctx.trace]
    assert kinds[0] == "fix" and kinds[-1] == "arrive" and "detection" in kinds


def test_a_landmark_never_found_is_retried_then_avoided_by_a_replan(make_rig, pm):
    plan = FakePlanner().plan(pm, "4,0,0", "room13")
    hidden = next(s.look_for for s in plan.steps[1:-1] if s.look_for.startswith("room"))
    rig = make_rig(START, grounder=ScriptedGrounder(pm, hidden=frozenset({hidden})))
    out = rig.mission("Kitchen", max_ticks=MAX_TICKS)
    assert out.success, out.failure
    assert out.replans == 1
    replan = next(e for e in rig.ctx.trace if e.kind == "replan")
    assert replan.label.startswith("TARGET_NOT_FOUND") and hidden in replan.label
    searches = [e for e in rig.ctx.trace if e.kind == "plan"]
    assert len(searches) == 2 and all(hidden not in " ".join(e.data["steps"]) for e in searches[1:])


def test_the_root_cause_survives_a_failed_relocalization(make_rig, pm):
    # The goal's sign is covered (TARGET_NOT_FOUND); the recovery's re-localization then
    # reads no signs at all (LOCALIZATION_FAILED). The run reports both, root cause kept.
    grounder = ScriptedGrounder(pm, hidden=frozenset({"room13"}))
    rig = make_rig(
        START, grounder=grounder, overrides=("tree.replans=0", "tree.localization_attempts=1")
    )

    def blind_after_the_first_fix(tree):
        if any(e.kind == "fix" for e in rig.ctx.trace):
            grounder.signs_readable = False

    out = rig.mission("Kitchen", max_ticks=MAX_TICKS, on_tick=blind_after_the_first_fix)
    assert not out.success
    assert out.failure.code == FailureCode.LOCALIZATION_FAILED
    assert out.cause is not None and out.cause.code == FailureCode.TARGET_NOT_FOUND
    assert "room13" in out.cause.message
    assert str(out.failure).endswith(f"(after {out.cause})")


def test_a_silent_camera_ends_the_run_with_sensor_timeout(make_rig):
    rig = make_rig(START, overrides=("tree.localization_attempts=2",))
    rig.body.observe_error = SensorError("no camera frame on /camera/image_raw for 1.0 s")
    out = rig.mission("Kitchen", max_ticks=MAX_TICKS)
    assert not out.success and out.failure.code == FailureCode.SENSOR_TIMEOUT


def test_a_buggy_back_end_ends_the_run_with_internal_error(make_rig, pm):
    grounder = ScriptedGrounder(pm, error=IndexError("list index out of range"))
    rig = make_rig(START, grounder=grounder, overrides=("tree.localization_attempts=1",))
    out = rig.mission("Kitchen", max_ticks=MAX_TICKS)
    assert not out.success and out.failure.code == FailureCode.INTERNAL_ERROR
    assert "IndexError: list index out of range" in out.failure.message


def test_an_exception_in_a_tick_is_a_failure_not_a_crash(make_rig):
    rig = make_rig(START)

    def broken_pose():
        raise RuntimeError("odometry message malformed")

    def break_after_a_second(tree):
        if rig.ctx.now() > 1.0:
            rig.body.pose = broken_pose

    out = rig.mission("Kitchen", max_ticks=MAX_TICKS, on_tick=break_after_a_second)
    assert not out.success and out.failure.code == FailureCode.INTERNAL_ERROR
    assert "RuntimeError: odometry message malformed" in out.failure.message


@pytest.mark.parametrize("variant", ["pmnav", "coarse_only"])
def test_both_tree_variants_arrive_on_doubles(make_rig, variant):
    rig = make_rig(START, overrides=(f"tree.variant={variant}",))
    out = rig.mission("room4", max_ticks=MAX_TICKS)
    assert out.success, out.failure
