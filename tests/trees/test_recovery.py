"""The recovery subtree on the test doubles: the recovery is chosen by the failure code
(BLOCKED backs up and faces the corridor, TARGET_NOT_FOUND turns round to look, TIMEOUT
waits, anything else needs none), and the root cause is kept through recoveries until a
new plan."""

from __future__ import annotations

import math

import py_trees
import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.decorators import ClockTimeout
from pmnav_bt.behaviours.planning import MakePlan, NoteFailure
from pmnav_bt.behaviours.recovery import BACKUP_LIMIT_M, BackUp
from pmnav_bt.failures import Failure, FailureCode, root_cause
from pmnav_bt.hazards import HazardKind, place
from pmnav_bt.seams import Pose2D
from pmnav_bt.trees.recovery import WAIT_S, recovery_subtree

RUNNING, SUCCESS, FAILURE = Status.RUNNING, Status.SUCCESS, Status.FAILURE
# fig2_hospital, on the start-turn1 corridor (x = 0, north-south), turned 45 deg off its
# axis towards the east wall: the nearer way along the corridor is south (-90 deg).
ASKEW = Pose2D(0.0, 20.0, math.radians(-45))
TOL = 0.035  # rotate_command stops within 0.03 rad


@pytest.mark.parametrize(
    "code, branch",
    [
        (FailureCode.BLOCKED, "BackOffWall"),
        (FailureCode.TARGET_NOT_FOUND, "LookBack"),
        (FailureCode.TIMEOUT, "WaitItOut"),
        (FailureCode.PLANNING_FAILED, "NoRecovery"),
        (None, "NoRecovery"),
    ],
)
def test_the_recovery_is_chosen_by_the_failure_code(make_rig, code, branch):
    rig = make_rig(ASKEW)
    if code is not None:
        rig.set(failure=Failure(code, "why"))
    recovery = recovery_subtree(rig.ctx)
    rig.expect(rig.run(recovery, max_ticks=300), SUCCESS)
    assert [c.name for c in recovery.children if c.status == SUCCESS] == [branch]
    assert rig.stopped()


def test_nothing_to_recover_from_succeeds_at_once_without_moving(make_rig):
    rig = make_rig(ASKEW)
    rig.ticks(recovery_subtree(rig.ctx), [SUCCESS])
    assert rig.true_pose() == ASKEW


def test_blocked_backs_up_straight_then_faces_along_the_corridor(make_rig):
    rig = make_rig(ASKEW)
    rig.set(failure=Failure(FailureCode.BLOCKED, "obstacle 0.3 m ahead"))
    recovery = recovery_subtree(rig.ctx)
    backed = []

    def backed_up() -> bool:
        back = recovery.children[0].children[1]
        if back.status == SUCCESS and not backed:
            backed.append(rig.true_pose())
        return False

    rig.expect(rig.run(recovery, max_ticks=300, until=backed_up), SUCCESS)
    (p,) = backed
    assert math.dist((p.x, p.y), (ASKEW.x, ASKEW.y)) == pytest.approx(BACKUP_LIMIT_M, abs=0.011)
    heading = math.atan2(ASKEW.y - p.y, ASKEW.x - p.x)
    assert rig.yaw_error(heading, ASKEW.yaw) < 1e-6  # straight back
    assert rig.yaw_error(rig.true_pose().yaw, math.radians(-90)) < TOL


def test_a_backup_the_body_refuses_is_done_as_far_as_it_went(make_rig):
    rig = make_rig(ASKEW)
    rig.body.blocked = True  # it cannot reverse either
    rig.ticks(BackUp("BackUp", rig.ctx), [RUNNING, SUCCESS])  # asked once, then refused
    assert rig.true_pose() == ASKEW
    assert rig.body.velocity_command == (0.0, 0.0)


def test_target_not_found_turns_round_to_look_back(make_rig):
    rig = make_rig(ASKEW)
    rig.set(failure=Failure(FailureCode.TARGET_NOT_FOUND, "room4 not seen in 7 views"))
    rig.expect(rig.run(recovery_subtree(rig.ctx), max_ticks=300), SUCCESS)
    p = rig.true_pose()
    assert rig.yaw_error(p.yaw, ASKEW.yaw + math.pi) < TOL
    assert (p.x, p.y) == pytest.approx((ASKEW.x, ASKEW.y))


def test_timeout_waits_on_the_clock_standing_still(make_rig):
    rig = make_rig(ASKEW)
    rig.set(failure=Failure(FailureCode.TIMEOUT, "Step took over 120 s"))
    rig.body.set_velocity(0.2, 0.0)  # whatever was going on is stopped
    t0 = rig.ctx.now()
    seen = rig.run(recovery_subtree(rig.ctx), max_ticks=300)
    rig.expect(seen, SUCCESS)
    assert WAIT_S <= rig.ctx.now() - t0 < WAIT_S + 0.15
    assert rig.true_pose() == ASKEW


def test_the_root_cause_is_kept_through_recoveries_until_a_new_plan(make_rig):
    rig = make_rig(ASKEW)
    root = Failure(FailureCode.TARGET_NOT_FOUND, "room4 not seen in 7 views")
    rig.set(goal="room17", failure=root)
    assert rig.tick(NoteFailure("NoteFailure", rig.ctx)) == SUCCESS
    assert rig.get("recovering_from") == root

    def timeout() -> ClockTimeout:
        slow = py_trees.behaviours.Running(name="Relocalize")
        return ClockTimeout("StepTimeout", slow, rig.ctx.now, 1.05)

    rig.ticks(timeout(), [RUNNING] * 11 + [FAILURE])
    second = rig.failure
    assert second.code == FailureCode.TIMEOUT and second.cause == root
    # Recovering from the second failure, the first is still the root cause.
    assert rig.tick(NoteFailure("NoteFailure", rig.ctx)) == SUCCESS
    assert rig.get("recovering_from") == root and root_cause(second) == root
    # A new plan ends the recovery: a later failure has no cause.
    rig.expect(rig.run(MakePlan("Plan", rig.ctx), max_ticks=5), SUCCESS)
    assert rig.get("recovering_from") is None
    rig.ticks(timeout(), [RUNNING] * 11 + [FAILURE])
    assert rig.failure.code == FailureCode.TIMEOUT and rig.failure.cause is None


def test_blocked_by_a_bump_at_the_side_backs_off_away_from_it(make_rig):
    """The body felt a bump on its left (bump_left, 72 deg off ahead): the back-off turns
    to face it and reverses straight off it, not back along its heading."""
    rig = make_rig(ASKEW)
    bump = place(HazardKind.BUMP, "bump_left", rig.true_pose(), rig.ctx.now())
    rig.body.hazards = lambda since=-math.inf: [bump]
    rig.body.blocked_by = lambda: bump
    rig.expect(rig.run(BackUp("BackUp", rig.ctx), max_ticks=300), SUCCESS)
    p = rig.true_pose()
    assert math.dist((p.x, p.y), bump.point) == pytest.approx(
        math.dist((ASKEW.x, ASKEW.y), bump.point) + BACKUP_LIMIT_M, abs=0.015
    )
    assert rig.stopped()
