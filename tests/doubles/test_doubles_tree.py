"""The whole PM-Nav tree on the seams' test doubles (no pybullet): a mission, retries
and a replan, and the failure codes a run reports (with its root cause)."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.backends import Backends
from pmnav_bt.config import load_config
from pmnav_bt.errors import SensorError
from pmnav_bt.failures import FailureCode
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.seams import Pose2D
from pmnav_bt.testing.doubles import (
    FakeBase,
    FakeCoarseDirection,
    FakePlanner,
    FakeRefiner,
    ScriptedGrounder,
)
from pmnav_bt.testing.oracle import ORACLE
from pmnav_bt.trees.runner import RunOutcome, make_context, run_tree

START = Pose2D(4.0, 0.0, 0.0)  # straight_office, facing east down the corridor
KITCHEN_DOOR = (48.5, 1.1)


def mission(
    pm: PrioriMap,
    goal: str = "Kitchen",
    *,
    grounder: ScriptedGrounder | None = None,
    base: FakeBase | None = None,
    overrides: tuple[str, ...] = (),
    on_tick=None,
    max_ticks: int = 20_000,
) -> tuple[RunOutcome, FakeBase, object]:
    base = base or FakeBase(START)
    backends = Backends(
        grounder or ScriptedGrounder(pm), FakeCoarseDirection(), FakeRefiner(), FakePlanner()
    )
    ctx = make_context(
        base, pm, load_config(overrides=[ORACLE, *overrides]), deferred_work=True, backends=backends
    )
    hook = (lambda tree: on_tick(ctx)) if on_tick is not None else None
    out = run_tree(ctx, goal, max_ticks=max_ticks, on_tick=hook)
    return out, base, ctx


def test_a_mission_on_doubles_reaches_the_goal_door(office):
    out, base, ctx = mission(office)
    assert out.success and out.failure is None, out.failure
    p = base.pose()
    assert math.dist((p.x, p.y), KITCHEN_DOOR) < 1.0
    assert out.fix_attempts == 1 and out.replans == 0
    kinds = [e.kind for e in ctx.trace]
    assert kinds[0] == "fix" and kinds[-1] == "arrive" and "detection" in kinds


def test_a_landmark_never_found_is_retried_then_avoided_by_a_replan(office):
    plan = FakePlanner().plan(office, "4,0,0", "room13")
    hidden = next(s.look_for for s in plan.steps[1:-1] if s.look_for.startswith("room"))
    grounder = ScriptedGrounder(office, hidden=frozenset({hidden}))
    out, base, ctx = mission(office, grounder=grounder)
    assert out.success, out.failure
    assert out.replans == 1
    replan = next(e for e in ctx.trace if e.kind == "replan")
    assert replan.label.startswith("TARGET_NOT_FOUND") and hidden in replan.label
    searches = [e for e in ctx.trace if e.kind == "plan"]
    assert len(searches) == 2 and all(hidden not in " ".join(e.data["steps"]) for e in searches[1:])


def test_the_root_cause_survives_a_failed_relocalization(office):
    # The goal's sign is covered (TARGET_NOT_FOUND); the recovery's re-localization then
    # reads no signs at all (LOCALIZATION_FAILED). The run reports both, root cause kept.
    grounder = ScriptedGrounder(office, hidden=frozenset({"room13"}))

    def blind_after_the_first_fix(ctx):
        if any(e.kind == "fix" for e in ctx.trace):
            grounder.signs_readable = False

    out, _, _ = mission(
        office,
        grounder=grounder,
        overrides=("tree.replans=0", "tree.localization_attempts=1"),
        on_tick=blind_after_the_first_fix,
    )
    assert not out.success
    assert out.failure.code == FailureCode.LOCALIZATION_FAILED
    assert out.cause is not None and out.cause.code == FailureCode.TARGET_NOT_FOUND
    assert "room13" in out.cause.message
    assert str(out.failure).endswith(f"(after {out.cause})")


def test_a_silent_camera_ends_the_run_with_sensor_timeout(office):
    base = FakeBase(START)
    base.observe_error = SensorError("no camera frame on /camera/image_raw for 1.0 s")
    out, _, _ = mission(office, base=base, overrides=("tree.localization_attempts=2",))
    assert not out.success and out.failure.code == FailureCode.SENSOR_TIMEOUT


def test_a_buggy_back_end_ends_the_run_with_internal_error(office):
    grounder = ScriptedGrounder(office, error=IndexError("list index out of range"))
    out, _, _ = mission(office, grounder=grounder, overrides=("tree.localization_attempts=1",))
    assert not out.success and out.failure.code == FailureCode.INTERNAL_ERROR
    assert "IndexError: list index out of range" in out.failure.message


def test_an_exception_in_a_tick_is_a_failure_not_a_crash(office):
    base = FakeBase(START)

    def broken_pose():
        raise RuntimeError("odometry message malformed")

    def break_after_a_second(ctx):
        if ctx.now() > 1.0:
            base.pose = broken_pose

    out, _, _ = mission(office, base=base, on_tick=break_after_a_second)
    assert not out.success and out.failure.code == FailureCode.INTERNAL_ERROR
    assert "RuntimeError: odometry message malformed" in out.failure.message


@pytest.mark.parametrize("variant", ["pmnav", "coarse_only"])
def test_both_tree_variants_arrive_on_doubles(office, variant):
    out, base, _ = mission(office, "room4", overrides=(f"tree.variant={variant}",))
    assert out.success, out.failure
